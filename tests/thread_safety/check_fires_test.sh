#!/usr/bin/env bash
# Proves scripts/check-thread-safety.sh refuses a lock misuse: runs it on a
# compile database that holds only counter_read_without_lock.cc, with the
# layers it checks pointed at this directory, and expects exit 1 naming the
# unguarded read.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
src=$root/tests/thread_safety/counter_read_without_lock.cc
printf '[{"directory": "%s", "command": "c++ -I%s -std=c++20 -c %s", "file": "%s"}]\n' \
  "$tmp" "$root" "$src" "$src" > "$tmp/compile_commands.json"
set +e
out=$(SURFMAP_THREAD_SAFETY_LAYERS=tests/thread_safety/ bash "$root/scripts/check-thread-safety.sh" "$tmp" 2>&1)
code=$?
set -e
echo "$out"
[ "$code" -eq 1 ] || { echo "check_fires: expected exit 1 from the check, got $code" >&2; exit 1; }
grep -q "reading variable 'count_' requires holding mutex 'mu_'" <<<"$out" ||
  { echo "check_fires: the check failed without naming the unguarded read" >&2; exit 1; }
echo "check_fires: the unguarded read is refused"
