#!/usr/bin/env bash
# The eight CC0 lat-long sample maps (Greg Zaal, HDRI Haven) used by tests and benchmarks.
# Uses ../shared/data/envmaps when it exists (developer checkouts); otherwise extracts them from
# Debian's blender-data package into .cache/envmaps (about 31 MB downloaded once, nothing installed).
set -euo pipefail
cd "$(dirname "$0")/.."
MAPS="city courtyard forest interior night studio sunrise sunset"
have_all() { for m in $MAPS; do [ -f "$1/$m.exr" ] || return 1; done; }
if have_all ../shared/data/envmaps || have_all .cache/envmaps; then exit 0; fi
echo "zhc setup: fetching the sample environment maps from Debian's blender-data package"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
(cd "$tmp" && apt-get download blender-data >/dev/null && dpkg -x blender-data_*.deb x)
mkdir -p .cache/envmaps
for m in $MAPS; do cp "$tmp/x/usr/share/blender/datafiles/studiolights/world/$m.exr" .cache/envmaps/; done
