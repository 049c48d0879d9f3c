#!/usr/bin/env bash
# Clang's thread-safety analysis over the threaded layers: every lock in
# server/base, server/jobs, server/service and storage is annotated
# (ABSL_GUARDED_BY, ABSL_EXCLUSIVE_LOCKS_REQUIRED, ...), and this check makes
# a missing or wrong annotation an error. It compiles each file with clang
# (-fsyntax-only: no objects, no link) using the flags CMake recorded in the
# build directory's compile_commands.json. In a unity build (the default:
# CMakeLists.txt, SURFMAP_UNITY_BUILD) it checks each batch CMake compiles,
# which includes the sources named in its #include lines, once.
#
# Usage: scripts/check-thread-safety.sh [BUILD_DIR]   (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${1:-${SURFMAP_BUILD_DIR:-build}}
CLANG=${CLANG:-$(command -v clang++-14 || command -v clang++ || true)}
[ -n "$CLANG" ] || { echo "check-thread-safety: clang++ not found (apt-get install clang-14)" >&2; exit 2; }
[ -f "$BUILD_DIR/compile_commands.json" ] || {
  echo "check-thread-safety: $BUILD_DIR/compile_commands.json is missing: configure the build first" >&2; exit 2; }
exec python3 - "$BUILD_DIR/compile_commands.json" "$CLANG" "$(nproc)" <<'PY'
import concurrent.futures, json, os, re, shlex, subprocess, sys

commands_file, clang, jobs = sys.argv[1], sys.argv[2], int(sys.argv[3])
# SURFMAP_THREAD_SAFETY_LAYERS (directories, space-separated) is for the
# check's own test (tests/thread_safety/), which points it at a wrong file.
layers = tuple(os.environ.get("SURFMAP_THREAD_SAFETY_LAYERS",
                              "server/base/ server/jobs/ server/service/ storage/").split())
root = os.getcwd() + "/"

def relative(path):
    path = os.path.realpath(path)
    return path[len(root):] if path.startswith(root) else None

def sources_of(path):
    """The project sources a compile covers: the file, or a unity batch's includes."""
    if "/Unity/unity_" not in path:
        return [relative(path)]
    return [relative(m) for m in re.findall(r'^#include "([^"]+)"', open(path).read(), re.M)]

entries = []
for e in json.load(open(commands_file)):
    path = os.path.realpath(e["file"])
    covered = [r for r in sources_of(path) if r and r.startswith(layers)]
    if not covered:
        continue
    rel = ", ".join(covered)
    args = shlex.split(e["command"]) if "command" in e else list(e["arguments"])
    # Drop the launcher and the compiler; keep defines, includes, standard.
    while args and not args[0].startswith("-"):
        args.pop(0)
    keep, skip = [], False
    for a in args:
        if skip:
            skip = False
            continue
        if a in ("-o", "-MF", "-MT", "-MQ"):
            skip = True
            continue
        if a in ("-c", "-MD") or a == e["file"] or a.endswith((".cc", ".cxx")):
            continue
        keep.append(a)
    entries.append((rel, e["directory"], keep + [path]))

def check(entry):
    rel, directory, args = entry
    cmd = [clang, "-fsyntax-only", "-Wthread-safety", "-Werror=thread-safety", "-Wno-unknown-warning-option"] + args
    r = subprocess.run(cmd, cwd=directory, capture_output=True, text=True)
    return rel, r.returncode, r.stderr if r.returncode else ""

# A compile database with nothing of the layers in it (a build configured
# without them, a wrong BUILD_DIR) would otherwise pass having checked nothing.
if not entries:
    print(f"check-thread-safety: no compile in {commands_file} covers {' '.join(layers)}", file=sys.stderr)
    sys.exit(2)

failed = 0
with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
    for rel, code, err in pool.map(check, sorted(entries)):
        if code:
            failed += 1
            print(f"FAIL {rel}\n{err}", flush=True)
files = sum(rel.count(", ") + 1 for rel, _, _ in entries)
print(f"check-thread-safety: {files} files in {len(entries)} compiles, {failed} with errors")
sys.exit(1 if failed else 0)
PY
