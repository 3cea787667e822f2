#!/usr/bin/env bash
# Installs (as root, with apt-get) the Debian 12 packages zhc needs that are missing, and makes
# sure the eight CC0 sample environment maps are available for tests and benchmarks.
# Safe to re-run: does nothing when everything is present.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  cmake ninja-build g++ pkg-config
  libopenexr-dev libtinygltf-dev libdraco-dev libmeshoptimizer-dev libzstd-dev libcli11-dev nlohmann-json3-dev libstb-dev
  libastcenc-dev libdeflate-dev libembree-dev
  libqhull-dev
  libgtest-dev libbenchmark-dev
  fonts-dejavu-core libpng-dev
  clang libclang-rt-14-dev
)
# Further packages needed only by some tests are listed in scripts/packages-test.txt.
if [ "${1:-}" = "--test" ] && [ -f scripts/packages-test.txt ]; then
  while read -r p; do [ -n "$p" ] && [ "${p#\#}" = "$p" ] && PACKAGES+=("$p"); done < scripts/packages-test.txt
fi

# Node.js + npm for the glTF client tests (tests/js): only when the commands are missing, since a
# machine may already have them from another packaging of Node.js (which provides npm itself).
if [ "${1:-}" = "--test" ] && { ! command -v node >/dev/null || ! command -v npm >/dev/null; }; then
  PACKAGES+=(nodejs npm)
fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "zhc setup: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

bash scripts/fetch_envmaps.sh
