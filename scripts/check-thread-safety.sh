#!/usr/bin/env bash
# Clang's thread-safety analysis over the threaded layers: every lock in
# server/base, server/jobs, server/service and storage is annotated
# (ABSL_GUARDED_BY, ABSL_EXCLUSIVE_LOCKS_REQUIRED, ...), and this check makes
# a missing or wrong annotation an error. It compiles each file with clang
# (-fsyntax-only: no objects, no link) using the flags CMake recorded in the
# build directory's compile_commands.json.
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
import concurrent.futures, json, os, shlex, subprocess, sys

commands_file, clang, jobs = sys.argv[1], sys.argv[2], int(sys.argv[3])
layers = ("server/base/", "server/jobs/", "server/service/", "storage/")
root = os.getcwd() + "/"
entries = []
for e in json.load(open(commands_file)):
    path = os.path.realpath(e["file"])
    rel = path[len(root):] if path.startswith(root) else None
    if rel is None or not rel.startswith(layers):
        continue
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
        if a in ("-c", "-MD") or a == e["file"] or a.endswith(".cc"):
            continue
        keep.append(a)
    entries.append((rel, e["directory"], keep + [path]))

def check(entry):
    rel, directory, args = entry
    cmd = [clang, "-fsyntax-only", "-Wthread-safety", "-Werror=thread-safety", "-Wno-unknown-warning-option"] + args
    r = subprocess.run(cmd, cwd=directory, capture_output=True, text=True)
    problems = [l for l in r.stderr.splitlines() if "thread-safety" in l or "error" in l]
    return rel, r.returncode, r.stderr if r.returncode else ""

failed = 0
with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
    for rel, code, err in pool.map(check, sorted(entries)):
        if code:
            failed += 1
            print(f"FAIL {rel}\n{err}", flush=True)
print(f"check-thread-safety: {len(entries)} files, {failed} with errors")
sys.exit(1 if failed else 0)
PY
