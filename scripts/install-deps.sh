#!/usr/bin/env bash
# Installs every Debian 12 (bookworm) package needed to build, test and run cia402. Idempotent: on a
# machine that already has them all it only asks dpkg and returns, without touching apt.
# The Python package needs pybind11 and Python's headers to build; NumPy is optional at run time
# (its tests take both paths) and matplotlib is not installed: examples/python/plot_run.py skips
# itself without it.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  googletest libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libfmt-dev libcpp-httplib-dev
  graphviz valgrind
  clang libclang-rt-14-dev
  gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib
  chromium python3-can python3-pytest
  pybind11-dev python3-pybind11 python3-dev python3-numpy
  iproute2 tshark
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [ "$status" = installed ] || missing+=("$p")
done
# Node.js for the browser test: Debian's nodejs and npm, unless a node and npm are already there
# (a NodeSource nodejs brings its own npm and conflicts with Debian's package).
command -v node >/dev/null || missing+=(nodejs)
command -v npm >/dev/null || missing+=(npm)

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages and Node.js already installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root (or install sudo)" >&2; exit 1; }
  sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
# Another apt run (unattended upgrades, a parallel job) may hold the lock: wait for it, not fail.
apt_opts=(-o DPkg::Lock::Timeout=600)
"${sudo[@]}" apt-get "${apt_opts[@]}" update
"${sudo[@]}" apt-get "${apt_opts[@]}" install -y --no-install-recommends "${missing[@]}"
