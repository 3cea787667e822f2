#!/usr/bin/env bash
# An engine adds zhc's source tree with add_subdirectory and gets the codec alone: configures
# tests/install/subdir_consumer with every third-party package zhc can look for disabled but Embree
# (the codec's one dependency: the bake's ray tracer), as on a machine with a C++ compiler, CMake and
# Debian's libembree-dev, builds it with the same generator as zhc (Ninja),
# checks that nothing of zhc::formats or the command was compiled, and runs it.
#   subdir.sh ZHC_SOURCE_DIR
set -euo pipefail
src=$(cd "$1" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
disabled=()
for pkg in OpenEXR Imath zstd nlohmann_json PkgConfig TinyGLTF draco meshoptimizer astcenc PNG CLI11 GTest benchmark; do
  disabled+=("-DCMAKE_DISABLE_FIND_PACKAGE_${pkg}=ON")
done
cmake -S "$src/tests/install/subdir_consumer" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DZHC_SOURCE_DIR="$src" "${disabled[@]}" >"$work/configure.log" 2>&1 ||
  { cat "$work/configure.log" >&2; echo "subdir: configuring a codec-only consumer failed" >&2; exit 1; }
cmake --build "$work/build" >"$work/build.log" 2>&1 ||
  { tail -30 "$work/build.log" >&2; echo "subdir: building a codec-only consumer failed" >&2; exit 1; }
# Only zhc_codec's sources and the consumer were compiled.
if grep -E "(formats|cli|tests|bench|fuzz)/[^ ]*\.cpp\.o" "$work/build/build.ninja" >/dev/null; then
  echo "subdir: add_subdirectory(zhc) compiles more than the codec:" >&2
  grep -oE "(formats|cli|tests|bench|fuzz)/[^ ]*\.cpp\.o" "$work/build/build.ninja" | sort -u | head >&2
  exit 1
fi
[ -f "$work/build/zhc/include/zhc/codec.h" ] || { echo "subdir: umbrella header zhc/codec.h not generated" >&2; exit 1; }
"$work/build/codec_consumer"
