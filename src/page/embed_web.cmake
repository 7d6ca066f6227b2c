# Turns the page's files into a C++ source: one byte array per file and a table of them.
# cmake -DSOURCE_DIR=<dir> -DFILES="a;b" -DOUTPUT=<file.cpp> -P embed_web.cmake
set(types_html "text/html; charset=utf-8")
set(types_css "text/css; charset=utf-8")
set(types_js "text/javascript; charset=utf-8")
set(types_svg "image/svg+xml")

set(arrays "")
set(table "")
set(i 0)
foreach(name IN LISTS FILES)
  file(READ "${SOURCE_DIR}/${name}" hex HEX)
  string(LENGTH "${hex}" digits)
  math(EXPR size "${digits} / 2")
  # 32 bytes a line.
  string(REGEX REPLACE "([0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f])" "\\1\n" hex "${hex}")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
  get_filename_component(ext "${name}" LAST_EXT)
  string(SUBSTRING "${ext}" 1 -1 ext)
  set(type "${types_${ext}}")
  if(type STREQUAL "")
    set(type "application/octet-stream")
  endif()
  string(APPEND arrays "// ${name}\nconstexpr unsigned char file_${i}[] = {\n${bytes}0x00};\n\n")
  string(APPEND table "    {\"/${name}\", \"${type}\", file_${i}, ${size}},\n")
  math(EXPR i "${i} + 1")
endforeach()

set(text "// Generated from src/page/web by src/page/embed_web.cmake: do not edit.
#include \"web_assets.hpp\"

namespace cia402::page::web {
namespace {

${arrays}constexpr asset table[] = {
${table}};

}  // namespace

std::span<const asset> assets() noexcept { return table; }

}  // namespace cia402::page::web
")
# Rewrite only on change, so an unchanged page does not rebuild the library.
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
  if(old STREQUAL text)
    return()
  endif()
endif()
file(WRITE "${OUTPUT}" "${text}")
