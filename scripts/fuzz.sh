#!/usr/bin/env bash
# Builds the libFuzzer targets with clang + ASan + UBSan in build-fuzz/ and runs each for a bounded
# time (ZHC_FUZZ_SECONDS, default 20) on a copy of its committed seed corpus (with its dictionary
# when fuzz/dict/<name>.dict exists). Fails on any crash, leak or sanitizer report.
#   ZHC_FUZZ_SECONDS=600 bash scripts/fuzz.sh     # longer local campaigns
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${ZHC_FUZZ_SECONDS:-20}"
if [ ! -f build-fuzz/build.ninja ]; then
  cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
    -DCMAKE_CXX_COMPILER=clang++ -DZHC_BUILD_FUZZERS=ON -DZHC_BUILD_TESTS=OFF -DZHC_BUILD_BENCH=OFF >/dev/null
fi
cmake --build build-fuzz -j "$(nproc)" >/dev/null
status=0
for exe in build-fuzz/fuzz/fuzz_*; do
  [ -x "$exe" ] || continue
  name=$(basename "$exe")
  work=$(mktemp -d)
  [ -d "fuzz/corpus/$name" ] && cp -r "fuzz/corpus/$name/." "$work/"
  args=("$work" -max_total_time="$secs" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1)
  [ -f "fuzz/dict/$name.dict" ] && args+=(-dict="fuzz/dict/$name.dict")
  log="$work.log"
  if "$exe" "${args[@]}" >"$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    echo "fuzz $name: ok, $runs executions in ${secs}s"
  else
    echo "fuzz $name: FAILED"; tail -n 40 "$log"; status=1
  fi
  rm -rf "$work" "$log"
done
exit $status
