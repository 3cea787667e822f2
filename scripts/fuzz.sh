#!/usr/bin/env bash
# Builds the libFuzzer targets with clang + ASan + UBSan (build-san/, scripts/build_san.sh; shared
# with the sanitized test suite) and runs each for a bounded time (ZHC_FUZZ_SECONDS, default 20;
# ZHC_FUZZ_JOBS targets side by side, default one per core) on
# a copy of its committed seed corpus (with its dictionary when fuzz/dict/<name>.dict exists).
# Fails on any crash, leak, sanitizer report, timeout, or single allocation above 256 MB (no
# decoder may allocate much more than its input justifies; zhc's limits are far below that).
#   ZHC_FUZZ_SECONDS=600 bash scripts/fuzz.sh     # longer local campaigns
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${ZHC_FUZZ_SECONDS:-20}"
bash scripts/build_san.sh
status=0
jobs="${ZHC_FUZZ_JOBS:-$(nproc)}"  # fuzzers run side by side, one per core
mkdir -p build-san/fuzz-artifacts  # crashing inputs are kept here
results=$(mktemp -d)
run_one() {  # run_one EXE INDEX: one target; its report goes to $results/INDEX.txt, exit status to INDEX.rc
  local exe=$1 idx=$2 name work log
  name=$(basename "$exe")
  work=$(mktemp -d)
  [ -d "fuzz/corpus/$name" ] && cp -r "fuzz/corpus/$name/." "$work/"
  local args=("$work" -max_total_time="$secs" -rss_limit_mb=2048 -malloc_limit_mb=256 -timeout=10 -print_final_stats=1
              -artifact_prefix="build-san/fuzz-artifacts/$name-")
  [ -f "fuzz/dict/$name.dict" ] && args+=(-dict="fuzz/dict/$name.dict")
  log="$work.log"
  if "$exe" "${args[@]}" >"$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    echo "fuzz $name: ok, $runs executions in ${secs}s" >"$results/$idx.txt"
    echo 0 >"$results/$idx.rc"
  else
    { echo "fuzz $name: FAILED"; tail -n 40 "$log"; } >"$results/$idx.txt"
    echo 1 >"$results/$idx.rc"
  fi
  rm -rf "$work" "$log"
}
targets=()
for exe in build-san/fuzz/fuzz_*; do
  [ -x "$exe" ] && [ -f "$exe" ] || continue
  case "$exe" in *_replay) continue ;; esac
  targets+=("$exe")
done
# Batches of $jobs targets at a time; reports printed in target order.
for ((i = 0; i < ${#targets[@]}; i += jobs)); do
  for ((k = i; k < i + jobs && k < ${#targets[@]}; ++k)); do run_one "${targets[k]}" "$k" & done
  wait
  for ((k = i; k < i + jobs && k < ${#targets[@]}; ++k)); do
    cat "$results/$k.txt"
    [ "$(cat "$results/$k.rc" 2>/dev/null)" = 0 ] || status=1
  done
done
rm -rf "$results"
exit $status
