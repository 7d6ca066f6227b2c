#!/usr/bin/env bash
# Whether g++ inlines the compiled step into the loops the speed targets measure, at -O2 (the level
# the targets were set at) and -O3 (the release preset). The step is at the size where g++ -O2 stops
# inlining on its own, and a call there doubles the quiet cycle (docs/compiled-step.md): a change
# that tips it fails here, not only as a slower figure in a noisy bench run.
#   bash bench/inlining/inlined.sh [CXX]
# A step that is not inlined somewhere is emitted out of line, as a symbol of the object.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
cxx=${1:-g++}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
step='cia402::step(cia402::compiled_profile const&, cia402::axis&, cia402::drive_inputs const&)'
# At -O0 nothing is inlined, so the step must show there: otherwise the name above no longer
# matches the step's and the checks below would pass whatever the compiler did.
"$cxx" -std=c++20 -O0 -I"$root/include" -I"$root/bench" -c "$root/bench/compiled_bench.cpp" -o "$out/unoptimized.o"
if ! grep -qF "$step" <<<"$(nm -C "$out/unoptimized.o")"; then
  echo "inlining: the step's name '$step' is not in an -O0 object; update it here" >&2
  exit 1
fi
status=0
for level in -O2 -O3; do
  for source in bench/compiled_bench.cpp bench/instructions/instructions.cpp; do
    object="$out/$(basename "${source%.cpp}")$level.o"
    "$cxx" -std=c++20 "$level" -DNDEBUG -I"$root/include" -I"$root/bench" -c "$root/$source" -o "$object"
    symbols=$(nm -C "$object")
    if grep -qF "$step" <<<"$symbols"; then
      echo "inlining: $source at $level calls the compiled step instead of inlining it" >&2
      status=1
    else
      echo "inlining: $source at $level: the compiled step is inlined"
    fi
  done
done
exit "$status"
