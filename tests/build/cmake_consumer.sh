#!/usr/bin/env bash
# The installed CMake helper (cmake/zhcBuild.cmake) in a Ninja build: installs zhc into a fresh
# prefix, configures tests/build/consumer against it and checks that the depfiles drive the build:
# the first build bakes, a second does nothing, touching an environment map named only inside the
# scene re-bakes that scene alone, touching a glTF buffer re-bakes the glTF, touching the SH lightmap
# EXR re-encodes the lightmap (a {i} name's parts: test_depfile), and touching an unrelated file does nothing.
#   cmake_consumer.sh BUILD_DIR CONSUMER_SOURCE_DIR ENVMAP GLTF_DATA_DIR
set -euo pipefail
build=$1 consumer=$2 envmap=$3 gltf=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
zhc="$prefix/bin/zhc"
[ -f "$prefix/lib/cmake/zhc/zhcBuild.cmake" ] || { echo "zhcBuild.cmake missing from the prefix" >&2; exit 1; }

src="$work/assets"
mkdir -p "$src/scenes" "$src/maps" "$src/hall" "$src/lightmap"
cp "$envmap" "$src/maps/sky.exr"
cat > "$src/scenes/room.json" <<'JSON'
{"format": "zhc-scene", "version": 1,
 "probes": {"grid": {"min": [0, 0, 0], "max": [2, 2, 2], "counts": [2, 2, 2]}},
 "environment": {"map": "../maps/sky.exr"}}
JSON
cp "$gltf/gt_list.gltf" "$gltf/gt_list.bin" "$gltf/tex.png" "$src/hall/"
echo "not read by any step" > "$src/maps/unrelated.exr"
"$zhc" lightmap synth "$envmap" -o "$work/sh9.exr" --size 8 --threads 1 >/dev/null
cp "$work/sh9.exr" "$src/lightmap/sh.exr"

b="$work/build"
cmake -S "$consumer" -B "$b" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" -DZHC_SCENE="$src/scenes/room.json" \
      -DZHC_GLTF="$src/hall/gt_list.gltf" -DZHC_LIGHTMAP="$src/lightmap/sh.exr" >/dev/null

steps() {  # the zhc commands a build ran, one word each: room, hall, lm
  local log=$1 out=""
  grep -q "zhc bake .*room.json" "$log" && out="$out room"
  grep -q "zhc bake .*gt_list.gltf" "$log" && out="$out hall"
  grep -q "zhc lightmap encode" "$log" && out="$out lm"
  echo "${out# }"
}
expect() {  # expect WHAT "room hall lm"
  local what=$1 want=$2 log="$work/log"
  ninja -C "$b" > "$log" 2>&1 || { cat "$log" >&2; echo "FAIL: $what: the build failed" >&2; exit 1; }
  local got; got=$(steps "$log")
  if [ "$got" != "$want" ]; then
    cat "$log" >&2
    echo "FAIL: $what: ran [$got], expected [$want]" >&2
    exit 1
  fi
  if ! grep -q "no work to do" <<< "$(ninja -C "$b" -n)"; then
    ninja -C "$b" -n -d explain >&2 || true
    echo "FAIL: $what: a second build would still run commands" >&2
    exit 1
  fi
  echo "ok: $what: ran [$got]"
}
later() { sleep 1; touch "$1"; }  # newer than the outputs whatever the clock granularity

expect "first build" "room hall lm"
for f in room.zhp room.zhp.d hall/lit.glb lm/room.iz.ktx2 lm/room.d.ktx2 lm/room.wa.ktx2 lm/phone.iz.ktx2 lm/phone.dwa.ktx2; do
  [ -s "$b/$f" ] || { echo "FAIL: $b/$f missing after the first build" >&2; exit 1; }
done
expect "nothing changed" ""
later "$src/maps/sky.exr"
expect "environment map behind the scene touched" "room"
later "$src/maps/unrelated.exr"
expect "unrelated file touched" ""
later "$src/hall/gt_list.bin"
expect "glTF buffer touched" "hall"
later "$src/hall/tex.png"
expect "glTF image (embedded into the .glb) touched" "hall"
later "$src/lightmap/sh.exr"
expect "lightmap EXR touched" "lm"
later "$src/scenes/room.json"
expect "scene touched" "room"
echo "build.cmake_consumer: depfiles drive the Ninja build"
