#!/usr/bin/env bash
# Installs every Debian 12 package that building, testing and running neuralmesh needs, the
# live viewer's three.js from the npm registry into client/web/node_modules, and the tests'
# independent E57 and LAZ readers (web-e57, laz-perf) into tests/tools/node_modules (`npm ci`,
# the versions pinned by each folder's package-lock.json).
# Idempotent: when everything is already installed it only checks and returns.
#
# Usage: scripts/install-deps.sh [EXTRA_PACKAGE...]
# Extra packages (e.g. podman for scripts/container-test.sh) are checked and installed with
# the others, so that `apt-get update` runs at most once.
set -euo pipefail

packages=(
  # Build tool chain.
  cmake g++ make ninja-build pkg-config git
  # Libraries fixed by the design card.
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libabsl-dev libdraco-dev libopenmesh-dev libgtest-dev libgmock-dev
  # zlib: the CRC-32 of the server's points journal; OpenSSL: HTTPS for the viewer and the
  # metrics page (gRPC needs both too).
  zlib1g-dev libssl-dev
  # Benchmarks.
  libbenchmark-dev
  # Tests and tools: the reference Draco binaries, an independent Python gRPC client, and
  # openssl for the throw-away certificates of the TLS tests.
  draco python3 python3-grpcio python3-grpc-tools python3-protobuf openssl
  # The live viewer's browser test: headless Chromium driven over the DevTools protocol.
  chromium python3-websocket
  "$@"
)
# npm, for three.js and web-e57: Debian's, unless the machine already has one (Node.js from
# another source brings its own npm, which Debian's package would conflict with).
if ! command -v npm >/dev/null 2>&1; then packages+=(npm); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
else
  echo "install-deps: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# npm packages, once per change of a lock file: three.js for the viewer (client/web), and the
# independent readers the tests check written files with (tests/tools: web-e57, laz-perf).
root="$(cd "$(dirname "$0")/.." && pwd)"
for dir in client/web tests/tools; do
  lock="${root}/${dir}/package-lock.json"
  if cmp -s "${lock}" "${root}/${dir}/node_modules/.installed-package-lock.json"; then
    echo "install-deps: ${dir}/node_modules up to date"
  else
    echo "install-deps: npm ci in ${dir}"
    (cd "${root}/${dir}" && npm ci --no-audit --no-fund --loglevel=error)
    cp "${lock}" "${root}/${dir}/node_modules/.installed-package-lock.json"
  fi
done
