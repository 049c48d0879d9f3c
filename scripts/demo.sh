#!/usr/bin/env bash
# demo: the Lloyd & Pai 2001 case study end to end on this machine.
#
# Builds surfmapd, surfmap and surfmap-rig, starts surfmapd on a free loopback
# port, uploads the simulated glass bottle with sandpaper patches, creates an
# adaptive friction job, lets two simulated rigs measure it until the plan
# completes, writes the map (out/demo/bottle_map.{png,ply,json}), scores it
# against the scene's truth and stops the server.
#
# Usage: scripts/demo.sh [--no-deps] [--no-build] [--rigs N] [--dashboard] [--realtime]
#   --no-deps    skip scripts/install-deps.sh (it needs root or sudo)
#   --no-build   use the binaries already in the build directory
#   --rigs N     simulated rigs in parallel (default 2)
#   --dashboard  also start the web dashboard (clients/dashboard, Node.js) on
#                DEMO_DASHBOARD_LISTEN (default 127.0.0.1:8080) before the rigs
#                run, print its URL, and keep surfmapd and the dashboard up after
#                the mapping until Ctrl-C
#   --realtime   the simulated rigs take each drag's real time (2 x 20 mm at
#                10 mm/s + pause: ~4.5 s a drag; the bottle takes ~4 min with
#                2 rigs), so the dashboard and `surfmap watch` run at lab pace
# Environment: SURFMAP_BUILD_DIR (default build); DEMO_JOB_ARGS adds options to
# `surfmap job create` to try other plans (e.g. "--mode adaptive --finest 1
# --threshold 4", the paper's rule); the default is the server's default job.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

INSTALL_DEPS=1
BUILD=1
RIGS=2
DASHBOARD=0
REALTIME=()
for arg in "$@"; do
  case "$arg" in
    --no-deps) INSTALL_DEPS=0 ;;
    --no-build) BUILD=0 ;;
    --dashboard) DASHBOARD=1 ;;
    --realtime) REALTIME=(--realtime) ;;
    --rigs=*) RIGS=${arg#--rigs=} ;;
    --rigs) RIGS=__next__ ;;
    -h|--help) sed -n '2,25p' "$0"; exit 0 ;;
    *)
      if [ "$RIGS" = "__next__" ]; then RIGS=$arg; else echo "demo: unknown argument '$arg'" >&2; exit 2; fi ;;
  esac
done
case "$RIGS" in ''|*[!0-9]*|0) echo "demo: --rigs needs a positive number" >&2; exit 2 ;; esac

# The plan: the server's default job (BOUNDARY): every vertex of the bottle's
# control mesh dragged in varied orientations, then drags placed and turned
# to cross the boundaries the drags so far suggest, up to 1.5 samples per
# control vertex; the map from every drag's pieces on ~2 mm edges.
JOB_ARGS=${DEMO_JOB_ARGS:-}

BUILD_DIR=${SURFMAP_BUILD_DIR:-build}
OUT=out/demo
SURFMAPD=$BUILD_DIR/server/service/surfmapd
SURFMAP=$BUILD_DIR/clients/cli/surfmap
RIG=$BUILD_DIR/clients/rig/surfmap-rig
MESH=clients/sim/scenes/bottle.obj

SERVER_PID=""
DASHBOARD_PID=""
RIG_PIDS=()
cleanup() {
  local status=$?
  if [ -n "$DASHBOARD_PID" ] && kill -0 "$DASHBOARD_PID" 2>/dev/null; then
    kill -TERM "$DASHBOARD_PID" 2>/dev/null || true
  fi
  for pid in "${RIG_PIDS[@]:-}"; do
    [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null || true
  done
  if [ -n "$SERVER_PID" ] && kill -0 "$SERVER_PID" 2>/dev/null; then
    echo "demo: stopping surfmapd (pid $SERVER_PID)"
    kill -TERM "$SERVER_PID" 2>/dev/null || true
    for _ in $(seq 1 150); do kill -0 "$SERVER_PID" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$SERVER_PID" 2>/dev/null || true
  fi
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

if [ "$INSTALL_DEPS" = 1 ]; then
  scripts/install-deps.sh
fi
if [ "$BUILD" = 1 ]; then
  scripts/build.sh --target surfmapd surfmap surfmap-rig
fi
for bin in "$SURFMAPD" "$SURFMAP" "$RIG"; do
  [ -x "$bin" ] || { echo "demo: $bin is missing: build it (scripts/build.sh --target surfmapd surfmap surfmap-rig)" >&2; exit 1; }
done

START=$(date +%s%N)
mkdir -p "$OUT"
rm -f "$OUT"/surfmap.db "$OUT"/surfmap.db-wal "$OUT"/surfmap.db-shm "$OUT"/port \
      "$OUT"/bottle_map.* "$OUT"/bottle_score.json "$OUT"/*.log
[ -f "$MESH" ] || { echo "demo: $MESH is missing (surfmap-write-scene-meshes clients/sim/scenes writes it)" >&2; exit 1; }

"$SURFMAPD" --listen 127.0.0.1:0 --db "$OUT/surfmap.db" --port-file "$OUT/port" --log-format text \
  >"$OUT/surfmapd.log" 2>&1 &
SERVER_PID=$!
for _ in $(seq 1 300); do
  [ -s "$OUT/port" ] && break
  if ! kill -0 "$SERVER_PID" 2>/dev/null; then
    SERVER_PID=""
    echo "demo: surfmapd exited during start-up; its log:" >&2
    cat "$OUT/surfmapd.log" >&2
    exit 1
  fi
  sleep 0.1
done
[ -s "$OUT/port" ] || { echo "demo: surfmapd did not write $OUT/port within 30 s" >&2; exit 1; }
export SURFMAP_SERVER=127.0.0.1:$(cat "$OUT/port")
unset SURFMAP_TOKEN
echo "demo: surfmapd (pid $SERVER_PID) listening on $SURFMAP_SERVER"

OBJECT=$("$SURFMAP" object upload "$MESH" --name bottle)
# shellcheck disable=SC2086  # JOB_ARGS is a list of options
JOB=$("$SURFMAP" job create --object "$OBJECT" --property friction --seed 2001 $JOB_ARGS)
echo "demo: object $OBJECT (bottle), job $JOB: the default friction job${JOB_ARGS:+ with $JOB_ARGS}"

if [ "$DASHBOARD" = 1 ]; then
  command -v node >/dev/null 2>&1 || { echo "demo: --dashboard needs Node.js (scripts/install-deps.sh installs it)" >&2; exit 1; }
  if [ ! -f clients/dashboard/node_modules/.package-lock.json ]; then
    (cd clients/dashboard && npm ci --no-audit --no-fund --loglevel=error)
  fi
  node clients/dashboard/server.js --server "$SURFMAP_SERVER" --listen "${DEMO_DASHBOARD_LISTEN:-127.0.0.1:8080}" \
    >"$OUT/dashboard.log" 2>&1 &
  DASHBOARD_PID=$!
  DASHBOARD_URL=""
  for _ in $(seq 1 200); do
    DASHBOARD_URL=$(sed -n 's/.*listening on \(http[^ ]*\).*/\1/p' "$OUT/dashboard.log")
    [ -n "$DASHBOARD_URL" ] && break
    kill -0 "$DASHBOARD_PID" 2>/dev/null || break
    sleep 0.1
  done
  if [ -z "$DASHBOARD_URL" ]; then
    echo "demo: the dashboard did not start; its log:" >&2
    cat "$OUT/dashboard.log" >&2
    exit 1
  fi
  echo "demo: dashboard (pid $DASHBOARD_PID) at $DASHBOARD_URL/#job=$JOB"
  if [ -t 0 ]; then
    # The mapping takes seconds: give a person time to open the page first.
    read -r -t "${DEMO_DASHBOARD_WAIT:-20}" -p "demo: open it, then press Enter to start the rigs (or wait ${DEMO_DASHBOARD_WAIT:-20} s) " _ || true
    echo
  fi
fi

# The first rig shows progress; the others run quietly. Each logs to a file too.
for i in $(seq 1 "$RIGS"); do
  name=rig-$i
  if [ "$i" = 1 ]; then
    "$RIG" --sim bottle --job "$JOB" --rig-id "$name" "${REALTIME[@]}" &
  else
    "$RIG" --sim bottle --job "$JOB" --rig-id "$name" --quiet "${REALTIME[@]}" >"$OUT/$name.log" 2>&1 &
  fi
  RIG_PIDS+=($!)
done
RIG_FAILED=0
for pid in "${RIG_PIDS[@]}"; do
  wait "$pid" || RIG_FAILED=1
done
RIG_PIDS=()
for i in $(seq 2 "$RIGS"); do
  tail -n 1 "$OUT/rig-$i.log"
done
if [ "$RIG_FAILED" = 1 ]; then
  echo "demo: a rig failed (logs in $OUT/rig-*.log, server log $OUT/surfmapd.log)" >&2
  exit 1
fi

"$SURFMAP" job show "$JOB" | tee "$OUT/job.txt"
# The job's total (progress.measured), not the first level's count.
SAMPLES=$("$SURFMAP" job show "$JOB" --json 2>/dev/null |
  python3 -c 'import json, sys; print(json.load(sys.stdin)["progress"]["measured"])' 2>/dev/null || true)
grep -q "COMPLETED" <(head -n 1 "$OUT/job.txt") || { echo "demo: job $JOB did not complete" >&2; exit 1; }

"$SURFMAP" map get "$JOB" --format json -o "$OUT/bottle_map.json"
"$SURFMAP" map get "$JOB" --format png -o "$OUT/bottle_map.png" --view -1,0,0
"$SURFMAP" map get "$JOB" --format ply -o "$OUT/bottle_map.ply"

echo
# Scored on the bottle's true surface (5,000 random points) through QueryMap.
"$RIG" score --sim bottle --job "$JOB" --json "$OUT/bottle_score.json" | tee "$OUT/score.txt"

if [ "$DASHBOARD" = 1 ]; then
  echo
  echo "demo: mapping finished; the dashboard stays up at $DASHBOARD_URL/#job=$JOB (surfmapd at $SURFMAP_SERVER)"
  echo "demo: press Ctrl-C to stop both and print the summary"
  # Ctrl-C ends this wait (and reaches surfmapd and the dashboard, which both
  # shut down cleanly on SIGINT); the summary below still runs.
  trap 'true' INT
  wait "$DASHBOARD_PID" 2>/dev/null || true
  trap 'exit 130' INT
  kill -TERM "$DASHBOARD_PID" 2>/dev/null || true
  wait "$DASHBOARD_PID" 2>/dev/null || true
  DASHBOARD_PID=""
fi

kill -TERM "$SERVER_PID" 2>/dev/null || true  # after Ctrl-C with --dashboard it may have stopped already
SERVER_STATUS=0
wait "$SERVER_PID" || SERVER_STATUS=$?
SERVER_PID=""
END=$(date +%s%N)

echo
echo "demo summary"
echo "  samples measured   ${SAMPLES:-?} (job $JOB)"
grep -E "mu RMSE|classified right" "$OUT/score.txt" | sed 's/^ */  /'
echo "  per region (truth vs map mean):"
sed -n '/region/,$p' "$OUT/score.txt" | sed 's/^ */    /'
awk -v a="$START" -v b="$END" 'BEGIN { printf "  elapsed            %.1f s (after the build)\n", (b - a) / 1e9 }'
echo "  files              $OUT/bottle_map.png $OUT/bottle_map.ply $OUT/bottle_map.json $OUT/bottle_score.json"
echo "  surfmapd exit code $SERVER_STATUS (log: $OUT/surfmapd.log)"
[ "$SERVER_STATUS" = 0 ] || exit 1
