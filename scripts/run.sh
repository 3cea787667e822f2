#!/usr/bin/env bash
# README command 1: install what is missing, build (Release), run the main job on the built-in default.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
./build/cli/zhc demo "$@"
