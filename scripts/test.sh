#!/usr/bin/env bash
# The test command: installs dependencies, builds everything, runs the fuzz
# smoke (four libFuzzer harnesses, 25 s each, in their own clang build) and the
# whole suite (unit + integration, real server on 127.0.0.1) with CTest.
#
# The fuzz smoke is a step here, not a CTest test: it builds a second tree with
# another compiler, which is not something a test of this build should do, and
# run alone it never competes for the two cores with the timing-sensitive
# integration tests. It runs before CTest so CTest's summary closes the output;
# a failed smoke still fails this script, after CTest has run.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
SURFMAP_WERROR=ON scripts/build.sh
fuzz_status=0
scripts/fuzz.sh --smoke || fuzz_status=$?
ctest --test-dir "${SURFMAP_BUILD_DIR:-build}" --output-on-failure -j2 --timeout 600
if [ "$fuzz_status" -ne 0 ]; then
  echo "test.sh: the fuzz smoke failed (exit $fuzz_status): see the fuzz.sh report above" >&2
  exit "$fuzz_status"
fi
