#!/usr/bin/env bash
# Builds the libFuzzer harnesses (tests/fuzz, clang-14 with ASan + UBSan, in
# their own build directory) and runs each for a bounded time on its seed
# corpus. Prints executions, exec/s, coverage (cov = edges, ft = features, from
# libFuzzer's final line) and corpus size per harness; on a crash, leak,
# sanitizer report, timeout or out-of-memory, the report and the reproducer's
# path. Exits non-zero if any harness failed.
#
# Usage: scripts/fuzz.sh [--smoke | --seconds N] [HARNESS...]
#   --smoke       25 s per harness (CI: all four in ~2 minutes after the build)
#   --seconds N   N s per harness (default 60); long campaigns: nice -n 10 scripts/fuzz.sh --seconds 900
#   HARNESS       trace_csv, obj, ply, trace_proto (default: all four)
# Environment: SURFMAP_FUZZ_BUILD_DIR (default build-fuzz);
#   SURFMAP_FUZZ_WORK (default $SURFMAP_FUZZ_BUILD_DIR/fuzz-work): per harness a
#   corpus/ that grows from run to run, seeds/ (rebuilt each run), artifacts/
#   (reproducers) and log.
# Replay a reproducer: build-fuzz/tests/fuzz/fuzz_HARNESS PATH
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

seconds=60
harnesses=()
while [ $# -gt 0 ]; do
  case "$1" in
    --smoke) seconds=25 ;;
    --seconds)
      [ $# -ge 2 ] || { echo "fuzz.sh: --seconds needs a number" >&2; exit 2; }
      seconds=$2; shift ;;
    trace_csv|obj|ply|trace_proto) harnesses+=("$1") ;;
    *) echo "fuzz.sh: unknown argument '$1' (harnesses: trace_csv obj ply trace_proto)" >&2; exit 2 ;;
  esac
  shift
done
case "$seconds" in ''|*[!0-9]*|0) echo "fuzz.sh: --seconds needs a whole number > 0, got '$seconds'" >&2; exit 2 ;; esac
[ ${#harnesses[@]} -gt 0 ] || harnesses=(trace_csv obj ply trace_proto)

build_dir=${SURFMAP_FUZZ_BUILD_DIR:-build-fuzz}
work=${SURFMAP_FUZZ_WORK:-$build_dir/fuzz-work}

# Toolchain check first: a clear message instead of a CMake error.
for tool in clang-14 clang++-14; do
  command -v "$tool" >/dev/null || { echo "fuzz.sh: $tool not found (scripts/install-deps.sh installs clang-14)" >&2; exit 2; }
done
if ! ls /usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  echo "fuzz.sh: libFuzzer runtime not found (scripts/install-deps.sh installs libclang-rt-14-dev)" >&2
  exit 2
fi

# Configure (once) and build. Only the harnesses' libraries are built: estimate,
# mesh, codec, the generated proto code. Serialised with the machine-wide build
# lock where there is one (shared development machines); CI has none.
build_start=$(date +%s)
if [ ! -f "$build_dir/build.ninja" ]; then
  launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSURFMAP_FUZZ=ON -DSURFMAP_BUILD_TESTS=OFF -DSURFMAP_BUILD_BENCHMARKS=OFF -DSURFMAP_BUILD_CLIENTS=OFF \
    "${launcher[@]}" >/dev/null
fi
build=(cmake --build "$build_dir" --target fuzz_harnesses -j"$(nproc)")
if [ -e /tmp/surfmap-build.lock ]; then build=(flock /tmp/surfmap-build.lock "${build[@]}"); fi
"${build[@]}" | grep -v '^\[' || true
[ "${PIPESTATUS[0]}" -eq 0 ] || { echo "fuzz.sh: build failed" >&2; exit 1; }
echo "fuzz.sh: build $(( $(date +%s) - build_start )) s"

# Stack traces with file:line (llvm-symbolizer comes with llvm-14).
if [ -x /usr/lib/llvm-14/bin/llvm-symbolizer ]; then
  export ASAN_SYMBOLIZER_PATH=/usr/lib/llvm-14/bin/llvm-symbolizer
fi
# UBSan is compiled with -fno-sanitize-recover=all (it aborts on its first
# report); print_stacktrace makes the report name where.
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

# Seeds of a harness: the files of the listed directories matching a glob
# (copied, so libFuzzer reads only inputs of the right kind), the committed
# hand-made seeds and every earlier crash's reproducer (tests/fuzz/regressions).
seed_sources() {
  case "$1" in
    trace_csv) echo "examples/traces/*.csv examples/traces/bad/*.csv tests/fuzz/seeds/trace_csv/*" ;;
    obj) echo "tests/data/meshes/*.obj" ;;
    ply) echo "tests/data/meshes/*.ply" ;;
    trace_proto) echo "tests/fuzz/seeds/trace_proto/*" ;;
  esac
}
# Input size caps (each harness also rejects longer inputs itself).
max_len() {
  case "$1" in
    trace_csv) echo 131072 ;;
    obj|ply) echo 65536 ;;
    trace_proto) echo 262144 ;;
  esac
}

failed=0
passed=0
summary=()
for h in "${harnesses[@]}"; do
  bin=$build_dir/tests/fuzz/fuzz_$h
  dir=$work/$h
  rm -rf "$dir/seeds" "$dir/artifacts"
  mkdir -p "$dir/corpus" "$dir/seeds" "$dir/artifacts"
  # shellcheck disable=SC2046  # the globs are meant to expand
  cp $(seed_sources "$h") "$dir/seeds/"
  if [ -d "tests/fuzz/regressions/$h" ]; then cp tests/fuzz/regressions/"$h"/* "$dir/seeds/"; fi
  dict=()
  if [ -f "tests/fuzz/dict/$h.dict" ]; then dict=(-dict="tests/fuzz/dict/$h.dict"); fi

  echo "fuzz.sh: $h for $seconds s ($(ls "$dir/seeds" | wc -l) seeds, $(ls "$dir/corpus" | wc -l) corpus inputs)"
  # One process (libFuzzer's default: no -jobs/-workers/-fork, which would fork
  # children logging to files). -timeout: an input running 25 s is a hang.
  status=0
  "$bin" -max_total_time="$seconds" -print_final_stats=1 -max_len="$(max_len "$h")" -timeout=25 \
    -rss_limit_mb=2560 "${dict[@]}" -artifact_prefix="$dir/artifacts/" \
    "$dir/corpus" "$dir/seeds" > "$dir/log" 2>&1 || status=$?

  # The last status line: "#N DONE cov: C ft: F corp: K/SIZE lim: L exec/s: E rss: R".
  last=$(grep -E '^#[0-9]+[[:space:]]+(DONE|INITED|NEW|REDUCE|pulse|RELOAD)' "$dir/log" | tail -1 || true)
  field() { echo "$last" | sed -nE "s/.* $1: ([^ ]+).*/\1/p"; }
  runs=$(sed -nE 's/^stat::number_of_executed_units: *([0-9]+)/\1/p' "$dir/log" | tail -1)
  rate=$(sed -nE 's/^stat::average_exec_per_sec: *([0-9]+)/\1/p' "$dir/log" | tail -1)
  line=$(printf '%-12s runs %-9s exec/s %-6s cov %-5s ft %-6s corpus %s' "$h" "${runs:-?}" "${rate:-?}" \
    "$(field cov)" "$(field ft)" "$(field corp)")
  if [ "$status" -eq 0 ]; then
    passed=$((passed + 1))
    summary+=("ok    $line")
  else
    failed=$((failed + 1))
    summary+=("FAIL  $line")
    echo "fuzz.sh: $h FAILED (exit $status); report from $dir/log:"
    # The sanitizer or FUZZ_CHECK report and libFuzzer's closing lines.
    grep -v -E '^#[0-9]+[[:space:]]|^"|Uses: [0-9]+$|^INFO: |^###### ' "$dir/log" | tail -60
    for artifact in "$dir"/artifacts/*; do
      [ -e "$artifact" ] || continue
      echo "fuzz.sh: reproducer $artifact ($(wc -c < "$artifact") bytes); replay: $bin $artifact"
    done
  fi
done

echo "fuzz.sh: results ($seconds s per harness; cov = edges, ft = features, corpus = inputs/size)"
printf '  %s\n' "${summary[@]}"
echo "fuzz: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
