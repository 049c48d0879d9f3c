#!/usr/bin/env bash
# Configures and builds surfmap in ./build (RelWithDebInfo: -O2 with line-table
# debug info, test code -O1; CMakeLists.txt says why).
# Usage: scripts/build.sh [cmake --build args, e.g. --target surfmapd]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${SURFMAP_BUILD_DIR:-build}
# SURFMAP_WERROR=ON|OFF (scripts/test.sh sets ON): warnings as errors; applied
# to an existing build tree too.
WERROR_ARG=${SURFMAP_WERROR:+-DSURFMAP_WERROR=$SURFMAP_WERROR}
if [ ! -f "$BUILD_DIR/build.ninja" ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo $WERROR_ARG
elif [ -n "$WERROR_ARG" ]; then
  cmake -S . -B "$BUILD_DIR" $WERROR_ARG >/dev/null
fi
cmake --build "$BUILD_DIR" -j"$(nproc)" "$@"
