#!/usr/bin/env bash
# Builds the libFuzzer targets with clang + ASan + UBSan (build-san/, scripts/build_san.sh; shared
# with the sanitized test suite) and runs each for a bounded time (ZHC_FUZZ_SECONDS, default 20) on
# a copy of its committed seed corpus (with its dictionary when fuzz/dict/<name>.dict exists).
# Fails on any crash, leak, sanitizer report, timeout, or single allocation above 256 MB (no
# decoder may allocate much more than its input justifies; zhc's limits are far below that).
#   ZHC_FUZZ_SECONDS=600 bash scripts/fuzz.sh     # longer local campaigns
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${ZHC_FUZZ_SECONDS:-20}"
bash scripts/build_san.sh
status=0
mkdir -p build-san/fuzz-artifacts  # crashing inputs are kept here
for exe in build-san/fuzz/fuzz_*; do
  [ -x "$exe" ] && [ -f "$exe" ] || continue
  case "$exe" in *_replay) continue ;; esac
  name=$(basename "$exe")
  work=$(mktemp -d)
  [ -d "fuzz/corpus/$name" ] && cp -r "fuzz/corpus/$name/." "$work/"
  args=("$work" -max_total_time="$secs" -rss_limit_mb=2048 -malloc_limit_mb=256 -timeout=10 -print_final_stats=1
        -artifact_prefix="build-san/fuzz-artifacts/$name-")
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
