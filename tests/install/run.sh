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
# The prefix holds exactly the public headers docs/api.md lists (plus the umbrella and runtime
# headers), and each compiles on its own against the prefix (it includes nothing left out).
docs=$(dirname "$0")/../../docs/api.md
want=$(grep -oE '^\| `(codec|formats)/[^`]+\.h`' "$docs" | sed -E 's/^\| `//; s/`$//' | sort)
have=$(cd "$prefix/include/zhc" && find codec formats -name '*.h' | sort)
if [ "$want" != "$have" ]; then
  echo "install: include/zhc differs from the public headers of docs/api.md:" >&2
  diff <(echo "$want") <(echo "$have") >&2 || true
  exit 1
fi
[ "$(echo "$want" | wc -l)" -ge 20 ] || { echo "install: docs/api.md lists too few public headers" >&2; exit 1; }
nl_inc=$(pkg-config --cflags nlohmann_json 2>/dev/null || true)
for h in $have codec.h formats.h; do
  # shellcheck disable=SC2086
  echo "#include <zhc/$h>" | c++ -std=c++20 -fsyntax-only -x c++ -I"$prefix/include" -I"$prefix/include/zhc" $nl_inc - ||
    { echo "install: include/zhc/$h does not compile on its own" >&2; exit 1; }
done

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
