#!/usr/bin/env bash
# Configures (once) and builds the sanitized tree build-san/: clang, AddressSanitizer +
# UndefinedBehaviorSanitizer (any UBSan finding aborts), with the test suite, the CLI and the
# libFuzzer targets in one build (one compile of the sources serves scripts/sanitize.sh and
# scripts/fuzz.sh). Warnings are errors here too (clang's -Wall -Wextra, as g++'s in scripts/test.sh).
# -gline-tables-only keeps stack traces symbolised at a fraction of -g's cost.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -f build-san/build.ninja ]; then
  cmake -S . -B build-san -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
    -DZHC_SANITIZE=ON -DZHC_BUILD_FUZZERS=ON -DZHC_REQUIRE_MESA_TEST=ON -DZHC_BUILD_TESTS=ON -DZHC_BUILD_BENCH=OFF -DZHC_WARNINGS_AS_ERRORS=ON >/dev/null
fi
# The build log is kept quiet but shown when the build fails (a failed build must never leave
# stale binaries to be tested).
if ! cmake --build build-san -j "$(nproc)" >build-san/build.log 2>&1; then
  grep -v '^\[' build-san/build.log | head -n 60
  echo "build_san: the sanitized build failed (full log: build-san/build.log)" >&2
  exit 1
fi
