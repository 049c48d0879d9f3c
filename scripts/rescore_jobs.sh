#!/usr/bin/env bash
# Scores again, with this build's map, the jobs that scripts/map_scenes.sh
# left behind: each SCENE.db under the given run directories (OUT/sN/) is
# copied, served by this build's surfmapd and scored on its scene's true
# surface (surfmap-rig score --job 1). The drags are the stored ones, so a
# change to how the map is built is measured without the planner choosing
# other drags. Prints one row per job: run directory, scene, % of the
# surface classified right, % in the worst region, mu RMSE.
#
#   scripts/rescore_jobs.sh RUN_DIR [RUN_DIR ...]    (e.g. out/map_scenes/s1)
#
# Environment: SURFMAP_BUILD_DIR (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${SURFMAP_BUILD_DIR:-build}
SURFMAPD=$BUILD/server/service/surfmapd
RIG=$BUILD/clients/rig/surfmap-rig
[ $# -gt 0 ] || { sed -n '2,13p' "$0" >&2; exit 2; }
for exe in "$SURFMAPD" "$RIG"; do
  [ -x "$exe" ] || { echo "rescore_jobs: $exe is missing (build first: scripts/build.sh)" >&2; exit 1; }
done
WORK=$(mktemp -d)
SERVER_PID=
cleanup() {
  if [ -n "$SERVER_PID" ]; then kill "$SERVER_PID" 2>/dev/null || true; fi
  rm -rf "$WORK"
}
trap cleanup EXIT
printf '%-32s %-16s %7s %7s %8s\n' run scene right% worst% muRMSE
for dir in "$@"; do
  shopt -s nullglob
  dbs=("$dir"/*.db)
  shopt -u nullglob
  [ ${#dbs[@]} -gt 0 ] || { echo "rescore_jobs: no *.db in $dir" >&2; exit 1; }
  for db in "${dbs[@]}"; do
    scene=$(basename "$db" .db)
    cp "$db" "$WORK/job.db"
    rm -f "$WORK/port"
    "$SURFMAPD" --listen 127.0.0.1:0 --db "$WORK/job.db" --port-file "$WORK/port" >"$WORK/surfmapd.log" 2>&1 &
    SERVER_PID=$!
    for _ in $(seq 1 300); do [ -s "$WORK/port" ] && break; sleep 0.1; done
    [ -s "$WORK/port" ] || { echo "rescore_jobs: surfmapd did not start on $db" >&2; cat "$WORK/surfmapd.log" >&2; exit 1; }
    SURFMAP_SERVER=127.0.0.1:$(cat "$WORK/port") "$RIG" score --sim "$scene" --job 1 --json "$WORK/score.json" \
      >/dev/null
    kill "$SERVER_PID"
    wait "$SERVER_PID" 2>/dev/null || true
    SERVER_PID=
    python3 - "$dir" "$scene" "$WORK/score.json" <<'PY'
import json, sys
run, scene, path = sys.argv[1:4]
score = json.load(open(path))
worst = min(r["classified_right"] for r in score["regions"]) if score["regions"] else 1.0
print(f"{run[-32:]:32s} {scene:16s} {100 * score['classified_right']:7.2f} {100 * worst:7.1f} {score['mu_rmse']:8.4f}")
PY
    rm -f "$WORK/job.db"*
  done
done
