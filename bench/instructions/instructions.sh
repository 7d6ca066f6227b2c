#!/usr/bin/env bash
# Instructions per step of the compiled step, the profile step and the master, each beside the bare
# lookup table, counted by valgrind's callgrind: the counts do not move with the machine's load.
#   bash bench/instructions/instructions.sh [build/release/bench/cia402_instructions] [PROFILE]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
program=${1:-"$here/../../build/release/bench/cia402_instructions"}
profile=${2:-cia402}
command -v valgrind >/dev/null || { echo "instructions: valgrind not found (Debian: valgrind)" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
per_step() {  # SCENARIO: instructions per step inside the scenario's own function
  local scenario=$1 steps total
  steps=$(valgrind --tool=callgrind --callgrind-out-file="$out/$scenario" \
            --toggle-collect="*::$scenario(*" "$program" "$scenario" "$profile" 2>/dev/null | awk '{print $1}')
  total=$(callgrind_annotate "$out/$scenario" 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1; exit}')
  awk -v t="$total" -v n="$steps" 'BEGIN { printf "%.1f", t / n }'
}
echo "instructions per step, profile $profile (callgrind; the lookup table is a bare 256-entry table):"
for pair in "quiet:table_quiet:compiled_quiet:core_quiet" \
             "transitions:table_transitions:compiled_transitions:core_transitions"; do
  IFS=: read -r what table compiled core <<<"$pair"
  t=$(per_step "$table"); c=$(per_step "$compiled"); p=$(per_step "$core")
  echo "  $what: lookup table $t, compiled step $c, profile step $p"
done
echo "  master: repeated status word $(per_step master_repeated), a new word in the same state $(per_step master_changing)"
