#!/usr/bin/env bash
# Builds zhc with AddressSanitizer + UndefinedBehaviorSanitizer (g++) in build-asan/ and runs the
# test suite under them.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -f build-asan/build.ninja ]; then
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DZHC_SANITIZE=ON -DZHC_BUILD_BENCH=OFF >/dev/null
fi
cmake --build build-asan -j "$(nproc)"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$(nproc)" -E "${ZHC_SANITIZE_EXCLUDE:-^$}"
