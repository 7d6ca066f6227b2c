#!/usr/bin/env bash
# Instructions per step of the compiled step, the profile step and the master, each beside the bare
# lookup table, counted by valgrind's callgrind: the counts do not move with the machine's load.
#   bash bench/instructions/instructions.sh [build/release/bench/cia402_instructions] [PROFILE]
# The step every layer runs, step(profile, ...), is held to the bounds of the open issue: 30
# instructions a quiet step, 45 a transition-heavy one. Each is judged in the output, and a step
# over its bound fails the script: CI runs it for each of the five built-in profiles, which all
# meet both (docs/compiled-step.md, "The step through a profile").
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
failed=0
for pair in "quiet:table_quiet:compiled_quiet:core_quiet:30" \
             "transitions:table_transitions:compiled_transitions:core_transitions:45"; do
  IFS=: read -r what table compiled core bound <<<"$pair"
  t=$(per_step "$table"); c=$(per_step "$compiled"); p=$(per_step "$core")
  if awk -v p="$p" -v b="$bound" 'BEGIN { exit !(p <= b) }'; then
    verdict="within its bound of $bound"
  else
    verdict="OVER its bound of $bound"
    failed=1
  fi
  echo "  $what: lookup table $t, compiled step $c, profile step $p ($verdict)"
done
echo "  master: repeated status word $(per_step master_repeated), a new word in the same state $(per_step master_changing)"
if [ "$failed" = 1 ]; then
  echo "instructions: the step through profile $profile is over its bound" >&2
  exit 1
fi
