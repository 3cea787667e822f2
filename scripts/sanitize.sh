#!/usr/bin/env bash
# Builds zhc with AddressSanitizer + UndefinedBehaviorSanitizer (clang, build-san/, see
# scripts/build_san.sh) and runs the whole test suite under them, leak checking on.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build_san.sh
# ZHC_TEST_SAMPLE_SCALE: the runtime-vs-codec comparisons run a tenth of their 100,000 probes here, and
# the slow brute-force twins (test::scaled_count, tests/runtime_c/check_decode.py) a tenth of their
# random inputs (memory errors and UB need the code paths, not the statistics; the Release run keeps
# the full counts and asserts the same).
# -LE gpu_driver: the comparisons with Mesa's CPU GPU drivers (lavapipe, llvmpipe; label set in
# tests/CMakeLists.txt) run in the Release pass only: sanitized, they exercise the driver, not zhc.
# -E docs.examples|docs.readme_choice: the Markdown examples and the README's generated tables run the
# same CLI paths as the conformance suite (which does run sanitized); they check the docs, and
# sanitized they would add minutes. ZHC_SANITIZE_EXCLUDE replaces this list.
ZHC_TEST_SAMPLE_SCALE=0.1 ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-san --output-on-failure -j "$(nproc)" -LE gpu_driver -E "${ZHC_SANITIZE_EXCLUDE:-^docs\.(examples|readme_choice)$}"
