#!/usr/bin/env python3
"""The README's table from scripts/map_scenes.sh --seeds: per scene the mean
over the seeds with the worst seed in brackets, and which scene-seeds meet the
map goals of issue 16 (>= 97 % classified right, the bottle 99.5 %; >= 85 %
in every region; mu RMSE <= 0.03; at most 1.5 samples per control vertex).

    python3 scripts/map_scenes_summary.py out/map_scenes/rows.tsv

rows.tsv: scene, seed, samples, control vertices, classified right, worst
region (shares), mu RMSE, boundary error map->truth and truth->map (mm).
"""
import sys
from collections import OrderedDict


def meets_goals(row):
    right_goal = 0.995 if row["scene"] == "bottle" else 0.97
    return (row["right"] >= right_goal and row["worst"] >= 0.85 and row["rmse"] <= 0.03
            and row["samples"] <= 1.5 * row["cvs"])


def read_rows(path):
    rows = []
    with open(path) as f:
        for line in f:
            p = line.rstrip("\n").split("\t")
            if len(p) != 9:
                continue
            rows.append({"scene": p[0], "seed": int(p[1]), "samples": int(p[2]), "cvs": int(p[3]),
                         "right": float(p[4]), "worst": float(p[5]), "rmse": float(p[6]),
                         "bnd": float(p[7]), "miss": float(p[8])})
    return rows


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    rows = read_rows(sys.argv[1])
    if not rows:
        sys.exit(f"map_scenes_summary: no rows in {sys.argv[1]}")
    by_scene = OrderedDict()
    for r in rows:
        by_scene.setdefault(r["scene"], []).append(r)
    seeds = sorted({r["seed"] for r in rows})
    print(f"\nSeeds {', '.join(map(str, seeds))}: mean over the seeds (worst seed in brackets)\n")
    print("| scene | samples (/ control vertices) | classified right | worst region | mu RMSE "
          "| boundary error mm (map->truth / truth->map) | goals met |")
    print("|---|---:|---:|---:|---:|---|---:|")
    met_total = 0
    missed = []
    for scene, rs in by_scene.items():
        n = len(rs)
        mean = lambda key: sum(r[key] for r in rs) / n
        met = [r for r in rs if meets_goals(r)]
        met_total += len(met)
        missed += [f"{scene} seed {r['seed']}" for r in rs if not meets_goals(r)]
        print(f"| {scene} | {mean('samples'):.0f} ({mean('samples') / rs[0]['cvs']:.2f}) "
              f"| {100 * mean('right'):.2f} ({100 * min(r['right'] for r in rs):.2f}) % "
              f"| {100 * mean('worst'):.1f} ({100 * min(r['worst'] for r in rs):.1f}) % "
              f"| {mean('rmse'):.4f} | {mean('bnd'):.2f} / {mean('miss'):.2f} | {len(met)} of {n} |")
    print(f"\nGoals met on {met_total} of {len(rows)} scene-seeds."
          + (f" Missed: {', '.join(missed)}." if missed else ""))


if __name__ == "__main__":
    main()
