#!/usr/bin/env bash
# The test command: installs dependencies, builds everything, runs the whole
# suite (unit + integration, real server on 127.0.0.1) with CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
ctest --test-dir "${SURFMAP_BUILD_DIR:-build}" --output-on-failure -j2 --timeout 600
