#!/usr/bin/env bash
# Regenerates the derived seed inputs under tests/fuzz/seeds/ from the example
# traces (run from anywhere; needs awk and protoc). The hand-written seeds
# (*.obj, *.ply, *.textproto without a CSV source) are not touched.
#
# - seeds/trace_csv/*.csv: example traces thinned to every k-th sample with 5-6
#   significant digits. Still fitted by FitTrace (32-64 samples), but 2-4 KB
#   instead of 70 KB, so each fuzzing run is ~20x faster and mutations land in
#   every part of the trace, not mostly in its middle.
# - seeds/trace_proto/*.bin: SubmitTraceRequest wire bytes (protoc --encode)
#   of thinned and full traces, and of the hand-written
#   seeds/trace_proto_text/*.textproto (kept apart: libFuzzer would read them
#   as wire bytes).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
seeds=$root/tests/fuzz/seeds
traces=$root/examples/traces

# thin SOURCE K DIGITS: every K-th data line of SOURCE, numbers to DIGITS digits.
thin() {
  awk -F, -v k="$2" -v d="$3" '
    /^#/ { next }
    /^t,/ { print; next }
    { if ((n++) % k) next
      for (i = 1; i <= 7; ++i) printf "%.*g,", d, $i
      print $8 }' "$1"
}

# textproto COMMAND_ID < CSV (columns in the order t,x,y,z,fx,fy,fz,phase)
textproto() {
  awk -F, -v id="$1" '
    /^#/ || /^t,/ { next }
    { ++n; for (i = 1; i <= 7; ++i) col[i] = col[i] (n > 1 ? ", " : "") $i
      ph = ph (n > 1 ? ", " : "") ($8 == "fwd" ? "PHASE_FORWARD" : $8 == "pause" ? "PHASE_PAUSE" : "PHASE_REVERSE") }
    END {
      split("t x y z fx fy fz", name, " ")
      printf "command_id: %d\nrig_id: \"rig-%d\"\nlease_next: true\nsamples {\n", id, id
      for (i = 1; i <= 7; ++i) printf "  %s: [%s]\n", name[i], col[i]
      printf "  phases: [%s]\n}\n", ph }'
}

encode() {
  protoc --encode=surfmap.v1.SubmitTraceRequest --proto_path="$root/proto" \
    "$root/proto/surfmap/v1/surfmap.proto"
}

mkdir -p "$seeds/trace_csv" "$seeds/trace_proto"
thin "$traces/glass_plane.csv" 8 6 > "$seeds/trace_csv/glass_plane_every8.csv"
thin "$traces/rubber_tilted_plane.csv" 8 6 > "$seeds/trace_csv/rubber_tilted_plane_every8.csv"
thin "$traces/masonite_cylinder.csv" 16 5 > "$seeds/trace_csv/masonite_cylinder_every16.csv"

textproto 1 < "$seeds/trace_csv/masonite_cylinder_every16.csv" | encode > "$seeds/trace_proto/masonite_cylinder_every16.bin"
textproto 2 < "$seeds/trace_csv/rubber_tilted_plane_every8.csv" | encode > "$seeds/trace_proto/rubber_tilted_plane_every8.bin"
textproto 3 < "$traces/sandpaper_sphere.csv" | encode > "$seeds/trace_proto/sandpaper_sphere.bin"
for t in "$seeds"/trace_proto_text/*.textproto; do
  name=$(basename "$t" .textproto)
  encode < "$t" > "$seeds/trace_proto/$name.bin"
done
echo "make_seeds: $(ls "$seeds"/trace_csv | wc -l) CSV and $(ls "$seeds"/trace_proto/*.bin | wc -l) proto seeds in $seeds"
