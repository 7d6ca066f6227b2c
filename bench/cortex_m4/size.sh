#!/usr/bin/env bash
# Cross-compiles the core for a Cortex-M4 (-Os -fno-exceptions -fno-rtti) and prints its flash and
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
flags=(-std=c++17 -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -Os
       -fno-exceptions -fno-rtti -ffunction-sections -fdata-sections -Wall -Wextra
       -I"$root/include" -I"$root/src/core")
core_sources=("$root"/src/core/drive.cpp "$root"/src/core/profile.cpp "$root"/src/core/names.cpp
              "$root"/src/core/master.cpp "$root"/src/core/profiles/*.cpp)
objects=()
for src in "${core_sources[@]}"; do
  obj="$out/$(basename "${src%.cpp}").o"
  "$cxx" "${flags[@]}" -c "$src" -o "$obj"
  objects+=("$obj")
done
link=(-Wl,--gc-sections --specs=nosys.specs)
"$cxx" "${flags[@]}" "$here/firmware.cpp" "${objects[@]}" "${link[@]}" -o "$out/firmware.elf"
"$cxx" "${flags[@]}" "$here/firmware_one_profile.cpp" "${objects[@]}" "${link[@]}" -o "$out/firmware_one_profile.elf"
"$cxx" "${flags[@]}" "$here/empty.cpp" "${link[@]}" -o "$out/empty.elf"
echo "== Cortex-M4 objects of the core (-Os, no exceptions, no RTTI)"
arm-none-eabi-size "${objects[@]}"
echo "== firmware with every built-in profile, with the standard profile alone, and without the core"
arm-none-eabi-size "$out/firmware.elf" "$out/firmware_one_profile.elf" "$out/empty.elf"
read -r e_text e_data e_bss _ < <(arm-none-eabi-size "$out/empty.elf" | tail -1)
report() {  # ELF, what it holds
  local text data bss
  read -r text data bss _ < <(arm-none-eabi-size "$1" | tail -1)
  echo "cortex-m4: $2: flash $(( (text + data) - (e_text + e_data) )) bytes, RAM $(( (data + bss) - (e_data + e_bss) )) bytes"
}
report "$out/firmware.elf" "drive-side machine with all built-in profiles, 5 axes"
report "$out/firmware_one_profile.elf" "drive-side machine with the cia402 profile alone, 1 axis"
