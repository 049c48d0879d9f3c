#!/usr/bin/env bash
# Configures and builds surfmap in ./build (Release with debug info).
# Usage: scripts/build.sh [cmake --build args, e.g. --target surfmapd]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${SURFMAP_BUILD_DIR:-build}
if [ ! -f "$BUILD_DIR/build.ninja" ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$BUILD_DIR" -j"$(nproc)" "$@"
