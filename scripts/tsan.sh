#!/usr/bin/env bash
# ThreadSanitizer over the threaded code: builds the unit tests of the
# threaded layers (base, storage, jobs), surfmapd and the integration tests
# with clang -fsanitize=thread in their own build directory, and runs them.
# Any race or lock-order report fails the run; reports are kept under
# BUILD_DIR/tsan-reports/ (the servers the integration tests start write
# theirs there too).
#
# Debian's gRPC, protobuf and abseil are not instrumented: races inside them
# cannot be seen, and their own synchronisation is invisible to TSan, so a
# hand-off between two gRPC threads can look like a race. scripts/tsan.supp
# lists the gRPC-internal frames suppressed for that reason; the project's own
# locks (server/base/mutex.h) are on pthreads, which TSan sees.
#
# Full debug info (SURFMAP_FULL_DEBUG_INFO): with line tables only (-g1, the
# default build) an inlined frame is symbolized by its bare name ("Unref"),
# and the suppressions, which name qualified functions, stop matching.
#
# Usage: scripts/tsan.sh [--no-build] [ctest -R regex]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD_DIR=${SURFMAP_TSAN_BUILD_DIR:-build-tsan}
case "$BUILD_DIR" in /*) ;; *) BUILD_DIR="$ROOT/$BUILD_DIR" ;; esac
BUILD=1
if [ "${1:-}" = "--no-build" ]; then BUILD=0; shift; fi
FILTER=${1:-'surfmap_base_test|surfmap_storage_test|surfmap_storage_testing_test|surfmap_jobs_test|surfmap_integration_test'}

command -v clang++-14 >/dev/null || { echo "tsan: clang++-14 is missing (scripts/install-deps.sh installs it)" >&2; exit 2; }
if [ "$BUILD" = 1 ]; then
  if [ ! -f "$BUILD_DIR/build.ninja" ]; then
    launcher=()
    command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
    CC=clang-14 CXX=clang++-14 cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_FLAGS="-fsanitize=thread -O1 -fno-omit-frame-pointer" \
      -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" -DSURFMAP_BUILD_BENCHMARKS=OFF "${launcher[@]}" \
      -DSURFMAP_FULL_DEBUG_INFO=ON
  fi
  lock=()
  [ -e /tmp/surfmap-build.lock ] && lock=(flock /tmp/surfmap-build.lock)
  "${lock[@]}" cmake --build "$BUILD_DIR" -j"$(nproc)" --target surfmapd surfmap_base_test surfmap_storage_test \
    surfmap_storage_testing_test surfmap_jobs_test surfmap_integration_test
fi

REPORTS="$BUILD_DIR/tsan-reports"
rm -rf "$REPORTS"
mkdir -p "$REPORTS"
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 history_size=4 suppressions=$ROOT/scripts/tsan.supp log_path=$REPORTS/report log_exe_name=1"
status=0
ctest --test-dir "$BUILD_DIR" -R "$FILTER" -j2 --timeout 1200 --output-on-failure || status=$?
reports=$(find "$REPORTS" -type f | wc -l)
if [ "$reports" -gt 0 ]; then
  echo "tsan: $reports report file(s):" >&2
  for f in "$REPORTS"/*; do echo "== $f" >&2; head -n 60 "$f" >&2; done
  status=1
fi
[ "$status" = 0 ] && echo "tsan: no reports"
exit "$status"
