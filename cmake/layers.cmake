# The layer rules of scripts/check_layers.py, enforced by the build where CMake can:
# - cia402_export_headers(): a target exports its own headers only. Its public include directory is a
#   folder of the build tree with links to its own part of include/cia402/, so a file compiles only
#   with the headers of the targets it links: an include of a layer the target does not link fails
#   at compile time ("No such file"), before the script reads it.
# - cia402_forbid_links(): a target's link closure must not reach the targets named, checked when
#   the project is configured: canopen and ethercat never link the simulator (nor drive402, which
#   does), the CoE codec links only the core, the master nothing of the slave side.

# The settings every C++20 library above the core shares: standard C++ without extensions, position
# independent (the Python package, a shared module, links it), the project's warnings.
function(cia402_cxx20_library target)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF POSITION_INDEPENDENT_CODE ON)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wconversion -Wshadow)
endfunction()

# A library above the core: `target` built from the sources that follow (STATIC first where it must
# be), with the settings every C++20 library shares, `include/cia402/<headers>` (a folder or a
# header) as its own headers and, for a whole layer, the name `cia402::<ALIAS>` others link it by.
# Each layer's folder, and each part of canopen/ and ethercat/, is one:
#   cia402_layer_library(cia402_axis axis ALIAS axis session.cpp ...)
function(cia402_layer_library target headers)
  cmake_parse_arguments(PARSE_ARGV 2 arg "" "ALIAS" "")
  add_library(${target} ${arg_UNPARSED_ARGUMENTS})
  if(arg_ALIAS)
    add_library(cia402::${arg_ALIAS} ALIAS ${target})
  endif()
  cia402_cxx20_library(${target})
  cia402_export_headers(${target} ${headers})
endfunction()

# Links `include/cia402/<item>` (a folder or a header) for `target` and makes the folder of links the
# target's public include directory (the installed tree stays CMAKE_INSTALL_INCLUDEDIR).
function(cia402_export_headers target)
  set(stage "${PROJECT_BINARY_DIR}/exported/${target}")
  foreach(item IN LISTS ARGN)
    set(link "${stage}/cia402/${item}")
    get_filename_component(parent "${link}" DIRECTORY)
    file(MAKE_DIRECTORY "${parent}")
    file(CREATE_LINK "${PROJECT_SOURCE_DIR}/include/cia402/${item}" "${link}" SYMBOLIC)
  endforeach()
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "INTERFACE_LIBRARY")
    target_include_directories(${target} INTERFACE "$<BUILD_INTERFACE:${stage}>")
  else()
    target_include_directories(${target} PUBLIC "$<BUILD_INTERFACE:${stage}>"
                                                "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  endif()
endfunction()

# Every target `target` links, directly or through others (aliases resolved; imported targets and
# plain library names are kept by name but not followed).
function(cia402_link_closure target out)
  set(seen "")
  set(todo ${target})
  while(todo)
    list(POP_FRONT todo t)
    if(t MATCHES "^\\$<LINK_ONLY:(.+)>$")
      set(t "${CMAKE_MATCH_1}")
    elseif(t MATCHES "^\\$<")
      continue()
    endif()
    if(TARGET ${t})
      get_target_property(aliased ${t} ALIASED_TARGET)
      if(aliased)
        set(t ${aliased})
      endif()
    endif()
    if(t IN_LIST seen)
      continue()
    endif()
    list(APPEND seen ${t})
    if(NOT TARGET ${t})
      continue()
    endif()
    get_target_property(imported ${t} IMPORTED)
    if(imported)
      continue()
    endif()
    get_target_property(direct ${t} LINK_LIBRARIES)
    get_target_property(interface ${t} INTERFACE_LINK_LIBRARIES)
    foreach(l IN LISTS direct interface)
      if(l AND NOT l MATCHES "-NOTFOUND$")
        list(APPEND todo ${l})
      endif()
    endforeach()
  endwhile()
  list(REMOVE_ITEM seen ${target})
  set(${out} ${seen} PARENT_SCOPE)
endfunction()

# Fails the configuration when `target` (if built) links any of the targets after FORBIDDEN.
function(cia402_forbid_links target)
  cmake_parse_arguments(arg "" "WHY" "FORBIDDEN" ${ARGN})
  if(NOT TARGET ${target})
    return()
  endif()
  cia402_link_closure(${target} closure)
  foreach(f IN LISTS arg_FORBIDDEN)
    if(f IN_LIST closure)
      message(FATAL_ERROR "${target} links ${f}: ${arg_WHY} (docs/architecture.md, scripts/check_layers.py)")
    endif()
  endforeach()
endfunction()
