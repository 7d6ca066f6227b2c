#!/usr/bin/env bash
# Cross-compiles the core for a Cortex-M4 (-Os -fno-exceptions -fno-rtti, no profile text) and prints its flash and
# RAM: arm-none-eabi-size of the core's objects, and of a firmware with and without it.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-"$root/build/cortex-m4"}
mkdir -p "$out"
cxx=arm-none-eabi-g++
if ! command -v "$cxx" >/dev/null; then
  echo "cortex-m4: $cxx not found (Debian: gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib)" >&2
  exit 1
fi
# CIA402_PROFILE_TEXT=0: a firmware has no use for the text the tools show (seed file, title).
flags=(-std=c++17 -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -Os
       -fno-exceptions -fno-rtti -ffunction-sections -fdata-sections -Wall -Wextra
       -DCIA402_PROFILE_TEXT=0 -I"$root/include" -I"$root/src/core")
core_sources=("$root"/src/core/drive.cpp "$root"/src/core/profile.cpp "$root"/src/core/names.cpp
              "$root"/src/core/master.cpp "$root"/src/core/profiles/*.cpp)
link=(-Wl,--gc-sections --specs=nosys.specs)

# build DIR [FLAG...]: the core's objects and the three firmwares, with the extra flags.
build() {
  local dir=$1
  shift
  mkdir -p "$dir"
  local objects=()
  for src in "${core_sources[@]}"; do
    local obj="$dir/$(basename "${src%.cpp}").o"
    "$cxx" "${flags[@]}" "$@" -c "$src" -o "$obj"
    objects+=("$obj")
  done
  for firmware in firmware firmware_one_profile; do
    "$cxx" "${flags[@]}" "$@" "$here/$firmware.cpp" "${objects[@]}" "${link[@]}" -o "$dir/$firmware.elf"
  done
  "$cxx" "${flags[@]}" "$@" "$here/empty.cpp" "${link[@]}" -o "$dir/empty.elf"
  core_objects=("${objects[@]}")
}

# report DIR HOW: each firmware's flash and RAM less the empty firmware's (the same registers read
# and written with nothing between them).
report() {
  local dir=$1 how=$2 e_text e_data e_bss text data bss
  read -r e_text e_data e_bss _ < <(arm-none-eabi-size "$dir/empty.elf" | tail -1)
  for pair in "firmware:drive-side machine with all built-in profiles, 5 axes" \
              "firmware_one_profile:drive-side machine with the cia402 profile alone, 1 axis"; do
    read -r text data bss _ < <(arm-none-eabi-size "$dir/${pair%%:*}.elf" | tail -1)
    echo "cortex-m4 ($how): ${pair#*:}: flash $(( (text + data) - (e_text + e_data) )) bytes," \
         "RAM $(( (data + bss) - (e_data + e_bss) )) bytes"
  done
}

build "$out/plain"
echo "== Cortex-M4 objects of the core (-Os, no exceptions, no RTTI)"
arm-none-eabi-size "${core_objects[@]}"
echo "== firmware with every built-in profile, with the standard profile alone, and without the core"
arm-none-eabi-size "$out/plain/firmware.elf" "$out/plain/firmware_one_profile.elf" "$out/plain/empty.elf"
# A firmware is usually linked with -flto: the step is then compiled into the firmware's loop.
build "$out/lto" -flto
report "$out/plain" "-Os"
report "$out/lto" "-Os -flto"
