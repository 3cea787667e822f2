#!/usr/bin/env bash
# README command 2: install what is missing, build (Release), run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --test
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j "$(nproc)"
