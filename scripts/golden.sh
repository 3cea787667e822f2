#!/usr/bin/env bash
# Regenerate tests/golden/metrics.tsv (tests/test_golden.cpp) after a deliberate change to a lossy
# path, and show what moved. Usage: scripts/golden.sh [BUILD_DIR]   (default: build)
# Prints every changed, added and removed row ("- old" / "+ new"), then git's summary of the file.
# Review the diff before committing: a hash change means different output bytes; a value change
# beyond its tolerance means a different error.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
[ -f "$build/build.ninja" ] || [ -f "$build/Makefile" ] || { echo "golden.sh: no configured build in $build" >&2; exit 2; }
cmake --build "$build" --target test_golden
ZHC_GOLDEN_REGENERATE=1 "$build/tests/test_golden" --gtest_filter=Golden.EveryLossyPathMatchesTheTable --gtest_brief=1
git --no-pager diff --stat -- tests/golden/metrics.tsv || true
