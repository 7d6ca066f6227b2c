#!/usr/bin/env bash
# Builds the libFuzzer targets (the `fuzz` preset: clang, ASan, UBSan) and runs each for SECONDS
# (default 30), starting from its corpus in tests/fuzz/corpus/. New inputs go to the build folder,
# not the repository; a crash leaves its reproducer there and fails the run.
#   bash tests/fuzz/run.sh [SECONDS] [TARGET...]
# A longer run: bash tests/fuzz/run.sh 3600 replay_fuzz
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
seconds=${1:-30}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(profile_file_fuzz scenario_file_fuzz replay_fuzz canopen_node_fuzz socketcand_fuzz
           eds_file_fuzz page_commands_fuzz page_http_text_fuzz ethercat_slave_fuzz ethercat_master_fuzz)
fi
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target "${targets[@]}"
out="$root/build/fuzz/runs"
mkdir -p "$out"
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
for t in "${targets[@]}"; do
  work="$out/$t"
  mkdir -p "$work/new" "$work/crashes"
  # -rss_limit_mb: memory stays bounded; -timeout: no input may hang (10 s, with the sanitizers on
  # a loaded machine).
  if ! "build/fuzz/tests/fuzz/$t" "$work/new" "tests/fuzz/corpus/$t" \
      -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
      -artifact_prefix="$work/crashes/" >"$work/log.txt" 2>&1; then
    status=1
    echo "fuzz: $t FAILED, see $work/log.txt and $work/crashes/" >&2
    tail -40 "$work/log.txt" >&2
    continue
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log.txt" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$work/log.txt" | tail -1 | cut -d' ' -f2)
  ft=$(grep -o 'ft: [0-9]*' "$work/log.txt" | tail -1 | cut -d' ' -f2)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$work/log.txt" | tail -1)
  echo "fuzz: $t: ${runs:-?} executions in ${seconds} s, coverage ${cov:-?} edges (${ft:-?} features), peak RSS ${rss:-?} MB"
done
exit $status
