#!/usr/bin/env bash
# Instructions per axis-step of the simulator: 1,000 csp axes at 1 kHz with the master's 0x607A
# write inside the step (sim_bench.cpp, one thread), counted by valgrind's callgrind inside
# machine::step_part (a thread's share of a cycle). Unlike the wall-clock realtime_factor, the
# figure does not move with the machine's load.
#   bash bench/instructions/sim_instructions.sh [build/release/bench/cia402_sim_bench]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
program=${1:-"$here/../../build/release/bench/cia402_sim_bench"}
command -v valgrind >/dev/null || { echo "sim instructions: valgrind not found (Debian: valgrind)" >&2; exit 1; }
out=$(mktemp)
trap 'rm -f "$out"' EXIT
valgrind --tool=callgrind --callgrind-out-file="$out" --toggle-collect='cia402::sim::machine::step_part*' \
  "$program" --benchmark_filter='sim_1000_axes_csp_1khz/threads:1/master_in_step:1' >/dev/null 2>&1
total=$(callgrind_annotate "$out" 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1; exit}')
# 1,000 axes through the 63 cycles that enable them and the 10,000 of the run, all in step_part.
awk -v t="$total" 'BEGIN { printf "sim csp: %.1f instructions per axis-step (1,000 axes, the 0x607A write included)\n", t / (1000 * 10063) }'
