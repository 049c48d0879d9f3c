#!/usr/bin/env bash
# deploy/container-entrypoint.sh outside a container (SURFMAP_DATA in a temp
# dir, SURFMAPD the built server, 127.0.0.1): with nothing mounted it makes a
# self-signed certificate and three tokens and starts surfmapd with TLS and
# tokens; the CLI with --ca-file and the read token lists objects, without a
# token it is refused, plaintext and a CA it does not trust fail; a second
# start reuses the certificate and the tokens; a mounted config without TLS is
# refused.
#
#   entrypoint_test.sh ENTRYPOINT SURFMAPD SURFMAP
set -euo pipefail

[[ $# -eq 3 ]] || { echo "usage: entrypoint_test.sh ENTRYPOINT SURFMAPD SURFMAP" >&2; exit 2; }
entrypoint=$1 surfmapd=$2 surfmap=$3
tmp=$(mktemp -d)
pid=""
cleanup() {
  [[ -n $pid ]] && kill "$pid" 2>/dev/null || true
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

start() {  # start -> $address; the entrypoint with SURFMAP_DATA=$tmp/data
  rm -f "$tmp/port"
  SURFMAP_DATA=$tmp/data SURFMAPD=$surfmapd SURFMAP_LISTEN=127.0.0.1:0 \
    "$entrypoint" --port-file "$tmp/port" --log-format text >> "$tmp/server.log" 2>&1 &
  pid=$!
  for _ in $(seq 1 400); do
    [[ -s $tmp/port ]] && break
    sleep 0.05
  done
  [[ -s $tmp/port ]] || { echo "surfmapd did not start; log:" >&2; cat "$tmp/server.log" >&2; exit 1; }
  address="127.0.0.1:$(tr -d '[:space:]' < "$tmp/port")"
}
stop() {
  kill "$pid"
  wait "$pid" || true
  pid=""
}
token_of() { sed -n "s/^ *\"\\([0-9a-f]*\\)\": \"$1\".*/\\1/p" "$tmp/data/tokens.json"; }

start
ca=$tmp/data/tls/server.pem
check "a self-signed certificate was made" test -s "$ca"
check "its key is private" test "$(stat -c %a "$tmp/data/tls/server.key")" = 600
check "three tokens were made" test "$(grep -c '"[0-9a-f]\{48\}"' "$tmp/data/tokens.json")" = 3
check "the server says it uses TLS and tokens" grep -q "auth=tokens transport=tls" "$tmp/server.log"
read_token=$(token_of read)
check "CLI --ca-file with the read token lists objects" \
  "$surfmap" --server "$address" --ca-file "$ca" --token "$read_token" --timeout 10 object list
check "CLI --ca-file without a token is refused (UNAUTHENTICATED)" \
  bash -c "'$surfmap' --server '$address' --ca-file '$ca' --timeout 10 object list 2>&1 | grep -q UNAUTHENTICATED"
check "CLI in plaintext fails" bash -c "! '$surfmap' --server '$address' --token '$read_token' --timeout 5 object list"
openssl req -x509 -newkey rsa:2048 -nodes -keyout "$tmp/other.key" -out "$tmp/other.pem" -days 1 \
  -subj /CN=other 2>/dev/null
check "CLI trusting another CA fails" \
  bash -c "! '$surfmap' --server '$address' --ca-file '$tmp/other.pem' --token '$read_token' --timeout 5 object list"
fingerprint=$(openssl x509 -in "$ca" -noout -fingerprint)
stop

start
check "a second start reuses the certificate" test "$(openssl x509 -in "$ca" -noout -fingerprint)" = "$fingerprint"
check "and the tokens" test "$(token_of read)" = "$read_token"
stop

# A config without TLS is refused (the container runs with TLS unless told).
mkdir -p "$tmp/plain"
echo '{"tokens": {"0123456789abcdef0123": "steer"}}' > "$tmp/plain/surfmapd.json"
set +e
SURFMAP_DATA=$tmp/plain SURFMAPD=$surfmapd SURFMAP_LISTEN=127.0.0.1:0 SURFMAP_CONFIG=$tmp/plain/surfmapd.json \
  "$entrypoint" > "$tmp/plain.log" 2>&1
rc=$?
set -e
check "a mounted config without TLS is refused (exit 2)" test "$rc" = 2
check "with a message naming tls_cert_file" grep -q "has no tls_cert_file" "$tmp/plain.log"

[[ $failures -eq 0 ]] || { echo "$failures check(s) failed; server log:"; cat "$tmp/server.log"; exit 1; }
echo "entrypoint_test: all checks passed"
