#!/usr/bin/env bash
# deploy/surfmap-backup.sh against a live surfmapd on 127.0.0.1: a backup
# taken while a rig is mapping the bottle is a consistent database, one taken
# after the job holds every trace, a server started on a copy serves the job
# as it was, rotation keeps the KEEP newest, and bad arguments fail with a
# message and leave no file behind.
#
#   backup_test.sh SURFMAPD SURFMAP SURFMAP_RIG BACKUP_SCRIPT BOTTLE_OBJ
set -euo pipefail

[[ $# -eq 5 ]] || { echo "usage: backup_test.sh SURFMAPD SURFMAP SURFMAP_RIG BACKUP_SCRIPT BOTTLE_OBJ" >&2; exit 2; }
surfmapd=$1 surfmap=$2 rig=$3 backup=$4 bottle=$5
for f in "$surfmapd" "$surfmap" "$rig" "$backup"; do [[ -x $f ]] || { echo "not executable: $f" >&2; exit 1; }; done
[[ -f $bottle ]] || { echo "missing mesh: $bottle" >&2; exit 1; }

tmp=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT
failures=0
check() {  # check DESCRIPTION COMMAND...
  local what=$1
  shift
  if "$@"; then echo "ok - $what"; else echo "not ok - $what"; failures=$((failures + 1)); fi
}

start_server() {  # start_server DB PORTFILE LOG -> sets $address
  rm -f "$2"
  "$surfmapd" --listen 127.0.0.1:0 --db "$1" --port-file "$2" --log-format text > "$3" 2>&1 &
  pids+=($!)
  for _ in $(seq 1 300); do
    [[ -s $2 ]] && break
    sleep 0.05
  done
  [[ -s $2 ]] || { echo "surfmapd did not start; log:" >&2; cat "$3" >&2; exit 1; }
  address="127.0.0.1:$(sed 's/.*://' "$2" | tr -d '[:space:]')"
}

db=$tmp/live/surfmap.db
mkdir -p "$tmp/live"
start_server "$db" "$tmp/port" "$tmp/server.log"
object=$("$surfmap" --server "$address" object upload "$bottle" --name bottle)
job=$("$surfmap" --server "$address" job create --object "$object" --property friction --mode adaptive \
  --coarsest 0 --finest 1 --threshold 4 --seed 2001)

# A backup while the rig submits traces.
"$rig" --server "$address" --sim bottle --job "$job" --rig-id backup-rig --quiet > "$tmp/rig.log" 2>&1 &
rig_pid=$!
pids+=("$rig_pid")
sleep 0.3
check "a backup during mapping succeeds" "$backup" "$db" "$tmp/backups" 5
wait "$rig_pid" || { echo "surfmap-rig failed:" >&2; cat "$tmp/rig.log" >&2; exit 1; }

live_traces=$(sqlite3 "$db" "SELECT COUNT(*) FROM traces")
during=$(find "$tmp/backups" -name 'surfmap-*.db' | sort | head -1)
during_traces=$(sqlite3 "$during" "SELECT COUNT(*) FROM traces")
check "the copy taken during mapping is consistent (integrity ok, $during_traces of $live_traces traces)" \
  test "$(sqlite3 "$during" 'PRAGMA integrity_check')" = ok -a "$during_traces" -le "$live_traces"
check "every trace of the copy has its fit" \
  test "$(sqlite3 "$during" 'SELECT COUNT(*) FROM traces t WHERE NOT EXISTS (SELECT 1 FROM fits f WHERE f.trace_id = t.id)')" = 0

check "a backup after the job succeeds" "$backup" "$db" "$tmp/backups" 5
after=$(find "$tmp/backups" -name 'surfmap-*.db' | sort | tail -1)
check "the copy after the job holds every trace ($live_traces)" \
  test "$(sqlite3 "$after" 'SELECT COUNT(*) FROM traces')" = "$live_traces"
check "no partial file is left behind" test -z "$(find "$tmp/backups" -name '*.partial')"

# A server on a copy of the backup serves the job as the live one does.
mkdir -p "$tmp/restored"
cp "$after" "$tmp/restored/surfmap.db"
start_server "$tmp/restored/surfmap.db" "$tmp/port2" "$tmp/server2.log"
restored_list=$("$surfmap" --server "$address" job list)
check "the restored server lists the job as COMPLETED" grep -Eq "^ +$job +$object +COMPLETED" <<< "$restored_list"
measured=$(sqlite3 "$db" "SELECT COUNT(*) FROM traces WHERE job_id = $job")
check "the restored job shows the $measured measured sites" grep -Eq "^ +$job .* $measured +0 " <<< "$restored_list"

# Rotation and bad arguments.
check "KEEP=1 keeps only the newest copy" "$backup" "$db" "$tmp/backups" 1
check "one copy is left" test "$(find "$tmp/backups" -name 'surfmap-*.db' | wc -l)" = 1
check "a missing database fails" bash -c "! '$backup' '$tmp/nope.db' '$tmp/b2' 2> '$tmp/err1'"
check "... naming it" grep -q "nope.db' does not exist" "$tmp/err1"
check "KEEP=0 fails" bash -c "! '$backup' '$db' '$tmp/b3' 0 2> '$tmp/err2'"
check "... saying why" grep -q "KEEP must be a whole number" "$tmp/err2"
check "a file that is not a database fails and leaves nothing" \
  bash -c "echo junk > '$tmp/junk.db'; ! '$backup' '$tmp/junk.db' '$tmp/b4' 2>/dev/null && test -z \"\$(ls -A '$tmp/b4' 2>/dev/null)\""

echo "$failures failure(s)"
[[ $failures -eq 0 ]]
