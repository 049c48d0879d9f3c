#!/usr/bin/env bash
# Installs every Debian 12 package surfmap needs to build, test and run.
# Run as root on a fresh machine (CI does); a no-op where they are present.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libeigen3-dev libosd-dev libsqlite3-dev sqlite3
  libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev libtinyobjloader-dev libstb-dev libmeshoptimizer-dev
  # glTF export of maps (server/haptics)
  libtinygltf-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  # TLS: libssl-dev for the server's constant-time token check (CRYPTO_memcmp,
  # SHA-256); openssl makes the throw-away CA and certificates of the TLS tests
  # and the container's self-signed certificate at first start.
  libssl-dev openssl
  # clang: the thread-safety analysis (scripts/check-thread-safety.sh), sanitizer
  # builds and fuzzing (scripts/fuzz.sh: libFuzzer and the sanitizer runtimes);
  # llvm-14 for llvm-symbolizer (file:line in sanitizer reports).
  clang-14 libclang-rt-14-dev libfuzzer-14-dev llvm-14
  # Python client (clients/python): Debian's runtime and test packages, no PyPI.
  python3 python3-grpcio python3-protobuf python3-numpy python3-matplotlib python3-pytest
  # Its checks: lint and types, and `pip install -e` into a venv (tests/test_packaging.py).
  flake8 mypy python3-venv python3-setuptools
  # Dashboard (clients/dashboard): Node.js runs its server; Chromium drives its browser test.
  nodejs chromium
)

missing=()
# The machine image may ship Node.js with npm inside the nodejs package;
# Debian's own nodejs needs the separate npm package.
command -v npm >/dev/null 2>&1 || missing+=(npm)
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
