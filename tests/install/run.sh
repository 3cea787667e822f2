#!/usr/bin/env bash
# Installs the build tree into a fresh prefix and builds two consumers outside the source tree
# against it: one with CMake's find_package(zhc), one with pkg-config. Both must compile, link and
# run (tests/install/consumer/main.cpp checks a projection -> zh3_q16 -> .zhp -> decode round trip).
#   run.sh BUILD_DIR CONSUMER_SOURCE_DIR ENVMAP
set -euo pipefail
build=$1 consumer=$2 envmap=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
for f in include/zhc/codec.h include/zhc/formats.h include/zhc/codec/probe/codec.h include/zhc/formats/probes/probe_file.h \
         lib/cmake/zhc/zhcConfig.cmake lib/cmake/zhc/zhcConfigVersion.cmake bin/zhc; do
  [ -e "$prefix/$f" ] || { echo "install: $f missing from the prefix" >&2; exit 1; }
done
pc=$(find "$prefix" -name zhc.pc)
[ -n "$pc" ] || { echo "install: zhc.pc missing from the prefix" >&2; exit 1; }
if [ -d "$(dirname "$0")/../../runtime" ]; then
  [ -d "$prefix/share/zhc/runtime" ] || { echo "install: share/zhc/runtime missing" >&2; exit 1; }
fi
# The installed command runs from the prefix.
"$prefix/bin/zhc" --version >/dev/null

# 1. CMake consumer, with the generator zhc itself is built with (Ninja: scripts/setup.sh installs
# ninja-build, not make, so CMake's default generator may have no build program on a fresh machine).
cmake -S "$consumer" -B "$work/cmake-build" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/cmake-build" >/dev/null
"$work/cmake-build/zhc_consumer" "$envmap"

# 2. pkg-config consumer (static libraries: --static pulls in the private dependencies).
flags=$(PKG_CONFIG_PATH="$(dirname "$pc")" pkg-config --static --cflags --libs zhc)
# shellcheck disable=SC2086
c++ -O1 "$consumer/main.cpp" -o "$work/pc-consumer" $flags
"$work/pc-consumer" "$envmap"
echo "install: find_package and pkg-config consumers built and ran against $prefix"
