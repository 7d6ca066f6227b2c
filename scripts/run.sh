#!/usr/bin/env bash
# Builds cia402 (release preset) and runs the main job: `cia402 serve`, the virtual drive and its
# instrument control page. It builds the Python package too (build/release/python: `PYTHONPATH=
# build/release/python python3 -c 'import cia402'`), when pybind11 is there (install-deps.sh). As root on a fresh Debian 12 it installs what
# it needs first. Arguments are passed to the job.
set -euo pipefail

# The main job: the one place to change what `bash scripts/run.sh` runs. A virtual drive with its
# instrument control page; it prints the URL (http://127.0.0.1:8402/) and stops on Ctrl-C.
main_job=(serve)

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/install-deps.sh
cmake --preset release
python_target=()
if grep -q '^cia402_python:' <(cmake --build --preset release --target help 2>/dev/null); then
  python_target=(cia402_python)
fi
cmake --build --preset release --target cia402 "${python_target[@]}"
exec "$root/build/release/tools/cia402" "${main_job[@]}" "$@"
