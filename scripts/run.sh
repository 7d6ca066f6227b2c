#!/usr/bin/env bash
# Builds cia402 (release preset) and runs the main job. As root on a fresh Debian 12 it installs what
# it needs first. Arguments are passed to the job.
set -euo pipefail

# The main job: the one place to change what `bash scripts/run.sh` runs.
main_job=(demo)

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/install-deps.sh
cmake --preset release
cmake --build --preset release --target cia402
exec "$root/build/release/tools/cia402" "${main_job[@]}" "$@"
