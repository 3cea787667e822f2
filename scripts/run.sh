#!/usr/bin/env bash
# README command 1: install what is missing, build (Release), run the main job on the built-in default.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
ZHC_BUILD_TARGET=zhc bash scripts/build.sh  # the command only: tests and benchmarks are the test command's
./build/cli/zhc demo "$@"
