#!/usr/bin/env bash
# The generated inputs of the README's and docs' examples (examples/README.md), from the eight sample
# maps, so that no image is checked in. Run from anywhere; the examples then run from the clone's root:
#
#   bash scripts/make_examples.sh            # writes into examples/ (the names are in .gitignore)
#   bash scripts/make_examples.sh OUTDIR     # writes into OUTDIR (the docs-examples test uses a temp folder)
#
# Sample maps: $ZHC_ENVMAP_DIR, else ../shared/data/envmaps, else .cache/envmaps (fetched from
# Debian's blender-data by scripts/fetch_envmaps.sh when neither is there), as the tests find them.
# Programs: $ZHC (default build/cli/zhc) and $ZHC_EXAMPLE_INPUTS (default
# build/examples/zhc_example_inputs; both built when missing), and exrmultipart (Debian `openexr`).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/examples}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"

maps="${ZHC_ENVMAP_DIR:-}"
if [ -z "$maps" ]; then
  if [ -f "$root/../shared/data/envmaps/city.exr" ]; then maps="$root/../shared/data/envmaps"
  else bash "$root/scripts/fetch_envmaps.sh"; maps="$root/.cache/envmaps"; fi
fi
zhc="${ZHC:-$root/build/cli/zhc}"
inputs="${ZHC_EXAMPLE_INPUTS:-$root/build/examples/zhc_example_inputs}"
if [ ! -x "$zhc" ] || [ ! -x "$inputs" ]; then
  cmake --build "$root/build" --target zhc zhc_example_inputs
fi
command -v exrmultipart >/dev/null || { echo "make_examples.sh: exrmultipart not found (install Debian's openexr)" >&2; exit 1; }

mkdir -p "$out/maps"
for m in city courtyard forest interior night studio sunrise sunset; do cp "$maps/$m.exr" "$out/maps/"; done
"$inputs" "$maps" "$out"
rm -f "$out/render.exr"
exrmultipart -combine -i "$out/render_diffuse.exr::diffuse" "$out/render_beauty.exr::beauty" -o "$out/render.exr" >/dev/null
rm -f "$out/render_diffuse.exr" "$out/render_beauty.exr"
"$zhc" convert "$root/examples/scattered.json" -o "$out/scattered.zhp" -r sh3 >/dev/null
echo "make_examples.sh: wrote maps/ (8 sample maps), sky.hdr, render.exr, linear.exr, L0.exr .. L8.exr, scattered.zhp in $out"
