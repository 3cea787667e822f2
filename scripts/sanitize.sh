#!/usr/bin/env bash
# Builds zhc with AddressSanitizer + UndefinedBehaviorSanitizer (clang, build-san/, see
# scripts/build_san.sh) and runs the whole test suite under them, leak checking on.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build_san.sh
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-san --output-on-failure -j "$(nproc)" -E "${ZHC_SANITIZE_EXCLUDE:-^$}"
