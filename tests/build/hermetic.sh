#!/usr/bin/env bash
# Hermetic outputs (docs/build-integration.md "Why the outputs are cacheable"): the same commands
# run twice on the same inputs, from two different folders, once with relative and once with
# absolute paths, with different TMPDIR, HOME, locale (LC_ALL=C vs C.UTF-8, both in every Debian
# libc), thread count and time zone (TZ=UTC0 vs TZ=XST-14, a POSIX TZ string that needs no tzdata;
# the clock itself is not moved: faketime is not a dependency), write byte-identical files: bake
# (.zhp, .glb from a JSON scene and from a glTF scene), convert, dering, lightmap synth, encode
# (KTX2 and DDS) and decode. The files name no path of the run. Reports are the files that name
# input paths; with --paths-relative-to they are identical too.
#   hermetic.sh ZHC ENVMAP GLTF_DATA_DIR
set -euo pipefail
zhc=$(realpath "$1") envmap=$(realpath "$2") gltf=$(realpath "$3")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

a="$work/a" b="$work/some other place/b"
mkdir -p "$a/maps" "$a/scenes" "$a/hall"
cp "$envmap" "$a/maps/sky.exr"
cat > "$a/scenes/room.json" <<'JSON'
{"format": "zhc-scene", "version": 1,
 "probes": {"grid": {"min": [0, 0, 0], "max": [2, 2, 1], "counts": [3, 3, 2]}},
 "environment": {"map": "../maps/sky.exr", "rotation_deg": 30},
 "lights": [{"type": "sphere", "center": [1, 1, 2], "radius": 0.3, "radiance": [4, 3, 2], "shadows": true}],
 "occluders": [{"type": "box", "min": [0.5, 0.5, 1.5], "max": [1.5, 1.5, 1.6]}]}
JSON
cp "$gltf/gt_list.gltf" "$gltf/gt_list.bin" "$gltf/tex.png" "$a/hall/"
mkdir -p "$(dirname "$b")"
cp -r "$a" "$b"

# run ROOT PREFIX OUT THREADS: every command, inputs named as PREFIX/..., outputs in OUT.
run() {
  local p=$2 out=$3 t=$4
  mkdir -p "$out"
  "$zhc" bake "$p/scenes/room.json" -o "$out/room.zhp" -r zh3_q16 --zstd 3 --threads "$t" --quiet >/dev/null
  "$zhc" bake "$p/scenes/room.json" -o "$out/room.glb" --threads "$t" --quiet >/dev/null
  "$zhc" bake "$p/hall/gt_list.gltf" -o "$out/hall.glb" --threads "$t" --quiet >/dev/null
  "$zhc" convert "$p/maps/sky.exr" -o "$out/sky.zhp" -r sh3_q28 --threads "$t" >/dev/null
  "$zhc" dering "$p/maps/sky.exr" -o "$out/sky.dering.json" --threads "$t" --paths-relative-to "$p" >/dev/null
  "$zhc" lightmap synth "$p/maps/sky.exr" -o "$out/sh.exr" --size 24 --threads "$t" >/dev/null
  "$zhc" lightmap encode "$out/sh.exr" -o "$out/lm" --quality fast --threads "$t" --quiet >/dev/null
  "$zhc" lightmap encode "$out/sh.exr" -o "$out/lm" --container dds --quality fast --threads "$t" --quiet >/dev/null
  "$zhc" lightmap decode "$out/lm" -o "$out/back.exr" --container ktx2 --quiet >/dev/null
  "$zhc" audit "$p/maps/sky.exr" -r sh3,zh3_q16 --no-timing --threads "$t" --quiet --paths-relative-to "$p" \
         --json --markdown "$out/audit.md" --html "$out/audit.html" > "$out/audit.json" 2>/dev/null
}

mkdir -p "$work/tmp1" "$work/tmp2" "$work/home1" "$work/home2"
(cd "$a" && env TMPDIR="$work/tmp1" HOME="$work/home1" LC_ALL=C TZ=UTC0 bash -c "set -euo pipefail; $(declare -f run); zhc='$zhc'; run . . out 1")
(cd / && env TMPDIR="$work/tmp2" HOME="$work/home2" LC_ALL=C.UTF-8 TZ=XST-14 bash -c "set -euo pipefail; $(declare -f run); zhc='$zhc'; run / '$b' '$b/out' 3")

files=(room.zhp room.glb hall.glb sky.zhp sky.dering.json sh.exr lm.iz.ktx2 lm.d.ktx2 lm.wa.ktx2 lm.iz.dds lm.d.dds lm.wa.dds
       back.exr audit.json audit.md audit.html)
for f in "${files[@]}"; do
  [ -s "$a/out/$f" ] || fail "$f not written"
  cmp -s "$a/out/$f" "$b/out/$f" || fail "$f differs between the two runs"
  for p in "$work" "$a" "$b" "some other place"; do
    if grep -qF "$p" "$a/out/$f" "$b/out/$f"; then fail "$f names a path of the run ($p)"; fi
  done
done
# Without --paths-relative-to the reports name the inputs as given, and differ.
(cd "$a" && "$zhc" audit maps/sky.exr -r sh3 --no-timing --quiet --json > "$work/rel.json")
"$zhc" audit "$b/maps/sky.exr" -r sh3 --no-timing --quiet --json > "$work/abs.json"
grep -qF '"maps/sky.exr"' "$work/rel.json" || fail "the JSON report does not name its input"
grep -qF "$b/maps/sky.exr" "$work/abs.json" || fail "the JSON report does not name its absolute input"
echo "build.hermetic: ${#files[@]} outputs identical across folder, path spelling, TMPDIR, HOME, LC_ALL, threads and TZ"
