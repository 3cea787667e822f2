#!/usr/bin/env bash
# README command 2: install what is missing, build (Release), run the whole test suite; then the
# same suite under ASan + UBSan, and every fuzzer for a bounded time (ZHC_FUZZ_SECONDS, default 20).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --test
bash scripts/build.sh -DZHC_REQUIRE_MESA_TEST=ON -DZHC_WARNINGS_AS_ERRORS=ON  # the Mesa decoder test must be built here; no warnings
ctest --test-dir build --output-on-failure -j "$(nproc)"
bash scripts/sanitize.sh
bash scripts/fuzz.sh
