#!/usr/bin/env bash
# Configures (once) and builds zhc in build/ (Release). Extra arguments go to cmake's configure.
# ZHC_BUILD_TARGET=NAME builds only that target and what it links (scripts/run.sh: the zhc command).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -f build/build.ninja ] || [ $# -gt 0 ]; then
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
fi
cmake --build build -j "$(nproc)" ${ZHC_BUILD_TARGET:+--target "$ZHC_BUILD_TARGET"}
