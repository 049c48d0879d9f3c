#!/bin/sh
# surfmapd in the container: TLS and bearer tokens are on unless you say
# otherwise. At first start, with nothing mounted, it makes
#   /data/tls/server.pem, server.key  a self-signed certificate (openssl) for
#                                     $SURFMAP_TLS_NAMES (default: the host
#                                     name, localhost, 127.0.0.1); clients pass
#                                     server.pem as --ca-file / ca_file=
#   /data/tokens.json                 three random tokens (read, probe, steer)
#   /data/surfmapd.json               the config using both
# and reuses them on every later start. Mount your own certificate at
# /etc/surfmap/tls/server.pem + server.key, or your own config at
# /etc/surfmap/surfmapd.json, to use those instead. A config without TLS or
# without tokens is refused unless SURFMAP_ALLOW_INSECURE=1 (a lab that
# terminates TLS elsewhere).
set -eu

DATA=${SURFMAP_DATA:-/data}
MOUNTED_CONFIG=${SURFMAP_CONFIG:-/etc/surfmap/surfmapd.json}
MOUNTED_TLS=${SURFMAP_TLS_DIR:-/etc/surfmap/tls}
mkdir -p "$DATA"
umask 077

if [ -f "$MOUNTED_CONFIG" ]; then
  CONFIG=$MOUNTED_CONFIG
else
  CONFIG=$DATA/surfmapd.json
  if [ -f "$MOUNTED_TLS/server.pem" ] && [ -f "$MOUNTED_TLS/server.key" ]; then
    CERT=$MOUNTED_TLS/server.pem KEY=$MOUNTED_TLS/server.key
  else
    CERT=$DATA/tls/server.pem KEY=$DATA/tls/server.key
    if [ ! -f "$CERT" ] || [ ! -f "$KEY" ]; then
      mkdir -p "$DATA/tls"
      host=$(hostname)
      names=${SURFMAP_TLS_NAMES:-DNS:$host,DNS:localhost,IP:127.0.0.1}
      openssl req -x509 -newkey rsa:3072 -nodes -days 825 -subj "/CN=$host" \
        -addext "subjectAltName=$names" -keyout "$KEY" -out "$CERT" 2>/dev/null
      chmod 644 "$CERT"
      echo "surfmap-entrypoint: made a self-signed certificate $CERT for $names; clients: --ca-file $CERT" >&2
    fi
  fi
  if [ ! -f "$DATA/tokens.json" ]; then
    printf '{\n  "%s": "read",\n  "%s": "probe",\n  "%s": "steer"\n}\n' \
      "$(openssl rand -hex 24)" "$(openssl rand -hex 24)" "$(openssl rand -hex 24)" > "$DATA/tokens.json"
    echo "surfmap-entrypoint: made three tokens (read, probe, steer) in $DATA/tokens.json" >&2
  fi
  printf '{\n  "tls_cert_file": "%s",\n  "tls_key_file": "%s",\n  "log_format": "json",\n  "tokens": %s}\n' \
    "$CERT" "$KEY" "$(cat "$DATA/tokens.json")" > "$CONFIG"
fi

if [ "${SURFMAP_ALLOW_INSECURE:-0}" != 1 ]; then
  grep -q '"tls_cert_file"' "$CONFIG" || { echo "surfmap-entrypoint: $CONFIG has no tls_cert_file (set SURFMAP_ALLOW_INSECURE=1 to run without TLS)" >&2; exit 2; }
  grep -q '"tokens"' "$CONFIG" || { echo "surfmap-entrypoint: $CONFIG has no tokens (set SURFMAP_ALLOW_INSECURE=1 to run open)" >&2; exit 2; }
fi
exec "${SURFMAPD:-/usr/local/bin/surfmapd}" --listen "${SURFMAP_LISTEN:-0.0.0.0:50051}" --db "$DATA/surfmap.db" --config "$CONFIG" "$@"
