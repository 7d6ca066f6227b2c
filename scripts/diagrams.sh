#!/usr/bin/env bash
# Draws every built-in profile's state machine from its table into docs/diagrams/ (DOT and SVG).
#   scripts/diagrams.sh CIA402_BINARY          write docs/diagrams/NAME.dot and NAME.svg
#   scripts/diagrams.sh CIA402_BINARY --check  fail if docs/diagrams/*.dot differ from the tables
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cia402=${1:?usage: diagrams.sh CIA402_BINARY [--check]}
mode=${2:-write}
out="$root/docs/diagrams"
mkdir -p "$out"
profiles=$("$cia402" profiles | awk '{print $1}')
status=0
for p in $profiles; do
  if [ "$mode" = --check ]; then
    if ! "$cia402" diagram --profile "$p" --format dot | diff -q - "$out/$p.dot" >/dev/null; then
      echo "diagrams: docs/diagrams/$p.dot is not what the $p table draws; run scripts/diagrams.sh" >&2
      status=1
    fi
    "$cia402" diagram --profile "$p" --format svg | grep -q '<svg' || {
      echo "diagrams: $p did not render to SVG" >&2
      status=1
    }
  else
    "$cia402" diagram --profile "$p" --format dot >"$out/$p.dot"
    "$cia402" diagram --profile "$p" --format svg >"$out/$p.svg"
  fi
done
[ "$mode" = --check ] && [ "$status" -eq 0 ] && echo "diagrams: docs/diagrams match every profile's table"
exit "$status"
