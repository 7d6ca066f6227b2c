#!/usr/bin/env bash
# Proves a consumer can use cia402 three ways, each building and running tests/consumer/main.cpp
# (which must exit 0: the drive reaches OPERATION ENABLED with status word 0x0237):
#   1. find_package(cia402 CONFIG) against an install into a temporary prefix (and, when the install
#      has it, cia402::profile_file through profile_file_consumer.cpp);
#   2. pkg-config against the same install, compiled with -fno-exceptions -fno-rtti;
#   3. add_subdirectory() of the source tree.
# Also checks that README.md's usage example is tests/consumer/main.cpp, word for word, and that the
# Python package, when built, imports from the prefix it was installed into.
# Extra cmake arguments for the library build: CIA402_CONSUMER_CMAKE_ARGS (e.g. -DCIA402_BUILD_TOOLS=OFF).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=${CIA402_JOBS:-2}
work=$(mktemp -d "${TMPDIR:-/tmp}/cia402-consumer.XXXXXX")
trap 'rm -rf "$work"' EXIT
consumer="$root/tests/consumer"
prefix="$work/prefix"

say() { printf '\n== test-consumer: %s\n' "$*"; }

say "README example is tests/consumer/main.cpp"
awk '/^```cpp$/ {inside=1; next} inside && /^```$/ {exit} inside {print}' "$root/README.md" \
  > "$work/readme_example.cpp"
if ! diff -u "$consumer/main.cpp" "$work/readme_example.cpp"; then
  echo "test-consumer: README.md's first cpp block differs from tests/consumer/main.cpp" >&2
  exit 1
fi

# Configured for the default prefix and installed elsewhere, either way: the package must be
# relocatable.
if [ -n "${CIA402_CONSUMER_BUILD:-}" ]; then
  say "install cia402 from $CIA402_CONSUMER_BUILD into a temporary prefix"
  cmake --install "$CIA402_CONSUMER_BUILD" --prefix "$prefix"
else
  say "build and install cia402 into a temporary prefix"
  # shellcheck disable=SC2086  # word splitting of the extra arguments is wanted
  cmake -S "$root" -B "$work/lib" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCIA402_BUILD_TESTS=OFF \
    ${CIA402_CONSUMER_CMAKE_ARGS:-}
  cmake --build "$work/lib" -j "$jobs"
  cmake --install "$work/lib" --prefix "$prefix"
fi
(cd "$prefix" && find . -type f | sort)
if [ -e "$prefix/bin/cia402" ]; then
  "$prefix/bin/cia402" --help > /dev/null
fi
# The Python package, when it was built (pybind11 found): it imports from where it was installed.
python_init=$(find "$prefix" -path '*/dist-packages/cia402/__init__.py' -print -quit)
if [ -n "$python_init" ]; then
  say "the Python package imports from the prefix"
  PYTHONPATH=$(dirname "$(dirname "$python_init")") /usr/bin/python3 -c \
    'import cia402; print(cia402.__version__, cia402.__file__); assert cia402.Drive().settle().transitions == [0, 1]'
fi

say "1/3 find_package(cia402 CONFIG)"
cmake -S "$consumer" -B "$work/find_package" -G Ninja -DCMAKE_PREFIX_PATH="$prefix"
cmake --build "$work/find_package" -j "$jobs"
"$work/find_package/consumer"
if [ -e "$prefix/include/cia402/profile_file.hpp" ]; then
  "$work/find_package/profile_file_consumer"  # cia402::profile_file and its toml++ link
fi

say "2/3 pkg-config cia402, -fno-exceptions -fno-rtti"
pc_file=$(find "$prefix" -name cia402.pc)
PKG_CONFIG_PATH=$(dirname "$pc_file")
export PKG_CONFIG_PATH
pkg-config --modversion cia402
mkdir -p "$work/pkg_config"
# shellcheck disable=SC2046  # pkg-config's output is a list of flags
c++ -std=c++17 -fno-exceptions -fno-rtti -Wall -Wextra -Wpedantic -Werror \
  "$consumer/main.cpp" -o "$work/pkg_config/consumer" $(pkg-config --cflags --libs cia402)
"$work/pkg_config/consumer"

say "3/3 add_subdirectory(cia402 source tree)"
cmake -S "$consumer" -B "$work/add_subdirectory" -G Ninja -DCIA402_CONSUMER_ADD_SUBDIRECTORY=ON \
  -DCIA402_SOURCE_DIR="$root"
cmake --build "$work/add_subdirectory" -j "$jobs"
"$work/add_subdirectory/consumer"

say "passed: find_package, pkg-config, add_subdirectory"
