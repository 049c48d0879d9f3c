#!/usr/bin/python3
"""Maps a scene twice with two refinement thresholds and compares them.

    threshold_experiment.py [--scene bottle] [--thresholds 2.0 8.0] [--finest 1]
                            [--server ADDR | --surfmapd PATH] [--rig PATH]

Without --server it starts its own surfmapd on 127.0.0.1 (a temp database).
For each threshold: upload the scene's mesh (once), create an adaptive
friction job, run simulated rigs (`surfmap-rig --sim SCENE`) until the plan
completes while following it with WatchJob, fetch the map with its mesh.

The truth per vertex is not available over gRPC (it lives in the scene file
of the simulated rig), so each map is written as a map file and scored by
`surfmap-rig score`, as scripts/demo.sh does: mu RMSE and worst error over the
map's vertices, the share of vertices nearest to their true material, and the
mean per region. The two maps are also compared with each other, vertex by
vertex (same finest level).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from typing import Dict, List

import numpy as np

import surfmap_client as sc
from surfmap_client.local_processes import find_binary, score_map

from example_lab import add_lab_arguments, measure, open_lab, scenes_dir


def parse_args(argv: List[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_lab_arguments(parser)
    parser.add_argument("--scene", default="bottle", help="simulated scene (bottle, plate)")
    parser.add_argument("--thresholds", type=float, nargs=2, default=[2.0, 8.0], metavar=("LOW", "HIGH"),
                        help="the two texture-distance thresholds (default 2.0 8.0: glass vs sandpaper is ~7.4)")
    parser.add_argument("--coarsest", type=int, default=0)
    parser.add_argument("--finest", type=int, default=1)
    parser.add_argument("--budget", type=int, default=0, help="max samples per job (0 = unlimited)")
    parser.add_argument("--seed", type=int, default=2001)
    parser.add_argument("--rigs", type=int, default=2, help="simulated rigs per job")
    return parser.parse_args(argv)


def run(args: argparse.Namespace) -> int:
    mesh = scenes_dir(args) / f"{args.scene}.obj"
    rig = find_binary("surfmap-rig", "SURFMAP_RIG", args.rig)
    os.environ.setdefault("SURFMAP_SCENES", str(scenes_dir(args)))  # for `surfmap-rig score`
    rows: List[Dict] = []
    maps: List[sc.SurfaceMap] = []
    with open_lab(args) as client, tempfile.TemporaryDirectory(prefix="surfmap-threshold-") as scratch:
        obj = client.upload_object(mesh, name=args.scene)
        print(f"object {obj.object_id}: {args.scene} ({obj.control_vertex_count} control vertices)",
              file=sys.stderr)
        for threshold in args.thresholds:
            started = time.monotonic()
            job = client.create_job(obj.object_id, sc.Property.FRICTION, sc.SamplingMode.ADAPTIVE,
                                    coarsest_level=args.coarsest, finest_level=args.finest, threshold=threshold,
                                    budget=args.budget, seed=args.seed)
            print(f"job {job.job_id}: threshold {threshold:g}", file=sys.stderr)
            done = measure(client, args, args.scene, job.job_id, rigs=args.rigs)
            if done.state != sc.JobState.COMPLETED:
                print(f"job {job.job_id} ended {done.state.name}, not COMPLETED", file=sys.stderr)
                return 1
            elapsed = time.monotonic() - started
            surface = client.get_map(job.job_id)
            path = os.path.join(scratch, f"map_{job.job_id}.json")
            sc.write_map_file(surface, path)
            score = score_map(rig, args.scene, path)
            maps.append(surface)
            rows.append({"threshold": threshold, "job": job.job_id, "samples": done.progress.measured,
                         "levels": {lp.level: lp.measured for lp in done.progress.levels},
                         "score": score, "uncertainty": float(np.nanmean(surface.mu_uncertainty)),
                         "elapsed": elapsed})
    print_comparison(args, rows, maps)
    return 0


def print_comparison(args: argparse.Namespace, rows: List[Dict], maps: List[sc.SurfaceMap]) -> None:
    print(f"scene {args.scene}: adaptive friction maps, levels {args.coarsest}..{args.finest}, seed {args.seed}"
          f"{', budget ' + str(args.budget) if args.budget else ''}")
    print("error against the scene's truth: `surfmap-rig score` on each map (truth is not served over gRPC)")
    print()
    levels = sorted({level for row in rows for level in row["levels"]})
    header = (f"{'threshold':>9} {'job':>4} {'samples':>7} "
              + " ".join(f"{'L' + str(level):>4}" for level in levels)
              + f" {'mu RMSE':>8} {'max err':>8} {'classified':>10} {'mean unc':>8} {'time s':>7}")
    print(header)
    for row in rows:
        s = row["score"]
        print(f"{row['threshold']:>9g} {row['job']:>4} {row['samples']:>7} "
              + " ".join(f"{row['levels'].get(level, 0):>4}" for level in levels)
              + f" {s['mu_rmse']:>8.4f} {s['mu_max_abs_error']:>8.4f} {100 * s['classification_accuracy']:>9.1f}%"
              f" {row['uncertainty']:>8.4f} {row['elapsed']:>7.1f}")
    print()
    print("per region, map mean (std) against the truth:")
    names = [region["name"] for region in rows[0]["score"]["regions"]]
    for i, name in enumerate(names):
        truth = rows[0]["score"]["regions"][i]["truth_mu"]
        cells = []
        for row in rows:
            region = row["score"]["regions"][i]
            mean, std = region["map_mu_mean"], region["map_mu_std"]
            cells.append(f"{mean:.3f} ({std:.3f})" if mean is not None else "-")
        print(f"  {name:<28} truth {truth:.3f}   " + "   ".join(
            f"t={row['threshold']:g}: {cell}" for row, cell in zip(rows, cells)))
    a, b = maps
    if a.vertex_count == b.vertex_count:
        diff = a.mu - b.mu
        print()
        print(f"map vs map (t={rows[0]['threshold']:g} minus t={rows[1]['threshold']:g}, {a.vertex_count} vertices): "
              f"rms {np.sqrt(np.nanmean(diff ** 2)):.4f}, max |diff| {np.nanmax(np.abs(diff)):.4f}")
    fewer = rows[1]["samples"] - rows[0]["samples"]
    print(f"the higher threshold took {abs(fewer)} {'fewer' if fewer < 0 else 'more'} samples "
          f"({rows[1]['samples']} vs {rows[0]['samples']})")


def main(argv: List[str]) -> int:
    args = parse_args(argv)
    try:
        return run(args)
    except sc.SurfmapError as error:
        print(f"threshold_experiment: {error}", file=sys.stderr)
        return 1
    except (RuntimeError, OSError) as error:
        print(f"threshold_experiment: {error}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
