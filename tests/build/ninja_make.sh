#!/usr/bin/env bash
# zhc's depfiles read by Ninja (deps = gcc, as CMake uses it) and by GNU Make (-include), with an
# environment map whose name needs escaping (a space, '#', '$', ':') named only inside the scene, and
# relative paths as a hand-written build file gives them. Each build system: the first build bakes,
# the second does nothing, touching the map re-bakes, touching an unrelated file does not.
#   ninja_make.sh ZHC ENVMAP
set -euo pipefail
zhc=$(realpath "$1") envmap=$(realpath "$2")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
later() { sleep 1; touch "$1"; }  # newer than the outputs whatever the clock granularity
setup() {  # a project folder: scenes/room.json -> "maps dir/c#it$y:1.exr"
  mkdir -p "$1/scenes" "$1/maps dir"
  cp "$envmap" "$1/maps dir/c#it\$y:1.exr"
  echo unrelated > "$1/maps dir/other.exr"
  cat > "$1/scenes/room.json" <<'JSON'
{"format": "zhc-scene", "version": 1, "probes": {"positions": [[0, 0, 0], [1, 0, 0]]},
 "environment": {"map": "../maps dir/c#it$y:1.exr"}}
JSON
}
fail() { echo "FAIL: $*" >&2; exit 1; }

# --- Ninja ---------------------------------------------------------------------------------------
n="$work/ninja"
setup "$n"
cat > "$n/build.ninja" <<EOF2
rule bake
  command = $zhc bake \$in -o \$out --depfile \$out.d --quiet
  depfile = \$out.d
  deps = gcc
build room.zhp: bake scenes/room.json
EOF2
grep -q <<< "$(cd "$n" && ninja)" "bake" || fail "ninja: first build did not bake"
[ -s "$n/room.zhp" ] || fail "ninja: room.zhp missing"
grep -qF <<< "$(cd "$n" && ninja -t deps room.zhp)" 'maps dir/c#it$y:1.exr' || fail "ninja: deps log lacks the map: $(cd "$n" && ninja -t deps)"
grep -q <<< "$(cd "$n" && ninja -n)" "no work to do" || fail "ninja: second build not empty"
later "$n/maps dir/c#it\$y:1.exr"
grep -qF <<< "$(cd "$n" && ninja -n -d explain 2>&1)" 'c#it$y:1.exr' || fail "ninja: touching the map does not re-bake"
(cd "$n" && ninja) >/dev/null
later "$n/maps dir/other.exr"
grep -q <<< "$(cd "$n" && ninja -n)" "no work to do" || fail "ninja: an unrelated file re-bakes"
echo "ok: ninja"

# --- GNU Make ------------------------------------------------------------------------------------
m="$work/make"
setup "$m"
printf 'room.zhp: scenes/room.json\n\t%s bake scenes/room.json -o $@ --depfile room.d --quiet\n-include room.d\n' "$zhc" > "$m/Makefile"
make -C "$m" -s >/dev/null
[ -s "$m/room.zhp" ] || fail "make: room.zhp missing"
grep -qF 'c\#it$$y\:1.exr' "$m/room.d" || fail "make: depfile lacks the escaped map: $(cat "$m/room.d")"
make -C "$m" -q || fail "make: second build not up to date"
later "$m/maps dir/c#it\$y:1.exr"
if make -C "$m" -q; then fail "make: touching the map does not re-bake"; fi
make -C "$m" -s >/dev/null
make -C "$m" -q || fail "make: not up to date after the re-bake"
later "$m/maps dir/other.exr"
make -C "$m" -q || fail "make: an unrelated file re-bakes"
echo "ok: make"
echo "build.ninja_make: Ninja and GNU Make read zhc's depfiles"
