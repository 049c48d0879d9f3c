#!/usr/bin/env bash
# Maps scenes through the real service, as a lab would: surfmapd with a fresh
# SQLite file, the scene's mesh uploaded, the DEFAULT job (only object and
# property given), simulated rigs (surfmap-rig --sim) until it completes, and
# the map scored on the scene's true surface through QueryMap
# (surfmap-rig score --job). Prints one table row per scene.
#
#   scripts/map_scenes.sh [--rigs N] [--seed N] [--check] [SCENE ...]   (default: all six)
#
# --check: exit 1 unless every scene meets the map goals (issue 16): >= 97 %
# of the true surface classified right, >= 85 % in every region, mu RMSE
# <= 0.03, at most 1.5 samples per control vertex.
# Environment: SURFMAP_BUILD_DIR (default build), MAP_SCENES_OUT (default
# out/map_scenes: databases, logs, score JSON).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${SURFMAP_BUILD_DIR:-build}
OUT=${MAP_SCENES_OUT:-out/map_scenes}
RIGS=2
SEED=1
SCENES=()
CHECK=0
while [ $# -gt 0 ]; do
  case "$1" in
    --rigs) RIGS=$2; shift 2 ;;
    --seed) SEED=$2; shift 2 ;;
    --check) CHECK=1; shift ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) SCENES+=("$1"); shift ;;
  esac
done
[ ${#SCENES[@]} -gt 0 ] || SCENES=(bottle plate banded_vase strip_block dotted_egg torus_handle)
SURFMAPD=$BUILD/server/service/surfmapd
SURFMAP=$BUILD/clients/cli/surfmap
RIG=$BUILD/clients/rig/surfmap-rig
for b in "$SURFMAPD" "$SURFMAP" "$RIG"; do
  [ -x "$b" ] || { echo "map_scenes: $b is not built (scripts/build.sh)" >&2; exit 1; }
done
mkdir -p "$OUT"
SERVER_PID=""
cleanup() { [ -n "$SERVER_PID" ] && kill -TERM "$SERVER_PID" 2>/dev/null && wait "$SERVER_PID" 2>/dev/null; true; }
trap cleanup EXIT

FAILED=0
printf "%-13s %7s %6s %7s %7s %8s %7s %7s %7s\n" scene samples "/CVs" "right%" "worst%" "muRMSE" "bnd mm" "miss mm" "time s"
for scene in "${SCENES[@]}"; do
  rm -f "$OUT/$scene.db"* "$OUT/$scene.port"
  "$SURFMAPD" --listen 127.0.0.1:0 --db "$OUT/$scene.db" --port-file "$OUT/$scene.port" \
    >"$OUT/$scene.surfmapd.log" 2>&1 &
  SERVER_PID=$!
  for _ in $(seq 1 300); do [ -s "$OUT/$scene.port" ] && break; sleep 0.1; done
  [ -s "$OUT/$scene.port" ] || { echo "map_scenes: surfmapd did not start (log $OUT/$scene.surfmapd.log)" >&2; exit 1; }
  export SURFMAP_SERVER=127.0.0.1:$(cat "$OUT/$scene.port")
  start=$(date +%s%N)
  # The scene's mesh as its JSON names it (several scenes may share one mesh).
  mesh=clients/sim/scenes/$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["mesh"])' "clients/sim/scenes/$scene.json")
  object=$("$SURFMAP" object upload "$mesh" --name "$scene" 2>"$OUT/$scene.upload.txt")
  job=$("$SURFMAP" job create --object "$object" --property friction --seed "$SEED" 2>"$OUT/$scene.job.txt")
  pids=()
  for i in $(seq 1 "$RIGS"); do
    "$RIG" --sim "$scene" --job "$job" --rig-id "rig-$i" --sim-seed "$((SEED * 100 + i))" --quiet \
      --spool "$OUT/spool-$scene-$i" >"$OUT/$scene.rig-$i.log" 2>&1 &
    pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid" || { echo "map_scenes: a rig failed ($OUT/$scene.rig-*.log)" >&2; exit 1; }; done
  end=$(date +%s%N)
  "$RIG" score --sim "$scene" --job "$job" --json "$OUT/$scene.score.json" >"$OUT/$scene.score.txt"
  samples=$("$SURFMAP" job show "$job" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["progress"]["measured"])')
  cvs=$(grep -c '^v ' "$mesh")
  python3 - "$OUT/$scene.score.json" "$scene" "$samples" "$cvs" "$start" "$end" "$CHECK" <<'PY' || FAILED=1
import json, sys
s = json.load(open(sys.argv[1]))
scene, samples, cvs, start, end = sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6])
worst = min(r["classified_right"] for r in s["regions"] if r["points"] > 0)
print(f"{scene:13s} {samples:7d} {samples / cvs:6.2f} {100 * s['classified_right']:7.2f} {100 * worst:7.2f} "
      f"{s['mu_rmse']:8.4f} {s['boundary_error_mm'] or float('nan'):7.2f} {s['missed_boundary_mm'] or float('nan'):7.2f} "
      f"{(end - start) / 1e9:7.1f}")
if sys.argv[7] == "1":
    missed = [name for name, ok in (("right% >= 97", s["classified_right"] >= 0.97), ("worst% >= 85", worst >= 0.85),
                                    ("mu RMSE <= 0.03", s["mu_rmse"] <= 0.03), ("samples/CVs <= 1.5", samples <= 1.5 * cvs))
              if not ok]
    if missed:
        print(f"{scene}: goal missed: {', '.join(missed)}")
        sys.exit(1)
PY
  kill -TERM "$SERVER_PID"; wait "$SERVER_PID" || true; SERVER_PID=""
done
exit "$FAILED"
