# Install rules: the core library as the exported package `cia402` (cia402::core), its headers, a
# version file, a pkg-config file, and the `cia402` tool when it is built. Tested from the outside by
# scripts/test-consumer.sh.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(CIA402_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/cia402"
    CACHE STRING "Where cia402Config.cmake is installed, relative to the prefix")

set(cia402_exported_targets cia402_core)
# The profile-file loader is exported when it is built. It links toml++, so the package config then
# finds that too (CIA402_EXPORTS_PROFILE_FILE is substituted into cia402Config.cmake).
set(CIA402_EXPORTS_PROFILE_FILE OFF)
if(TARGET cia402_profile_file)
  # The static profile-file library links the internal support library, so the export carries it.
  list(APPEND cia402_exported_targets cia402_support cia402_profile_file)
  set(CIA402_EXPORTS_PROFILE_FILE ON)
endif()

install(TARGETS ${cia402_exported_targets}
  EXPORT cia402_targets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})  # include dirs: each target's INSTALL_INTERFACE
# Only the headers of the exported libraries: the tools-side layers (diagram, replay, sim, canopen,
# ethercat, page, motion) are built for the cia402 tool and are not part of the package.
set(cia402_header_excludes PATTERN "diagram.hpp" EXCLUDE PATTERN "replay.hpp" EXCLUDE PATTERN "sim" EXCLUDE
    PATTERN "canopen" EXCLUDE PATTERN "ethercat" EXCLUDE PATTERN "page" EXCLUDE PATTERN "motion" EXCLUDE
    PATTERN "drive402" EXCLUDE PATTERN "apps" EXCLUDE PATTERN "axis" EXCLUDE)
if(NOT TARGET cia402_profile_file)
  list(APPEND cia402_header_excludes PATTERN "profile_file.hpp" EXCLUDE)  # no library for it
endif()
install(DIRECTORY "${PROJECT_SOURCE_DIR}/include/cia402"
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.hpp" ${cia402_header_excludes})
install(EXPORT cia402_targets
  NAMESPACE cia402::
  FILE cia402Targets.cmake
  DESTINATION ${CIA402_INSTALL_CMAKEDIR})

configure_package_config_file(
  "${CMAKE_CURRENT_LIST_DIR}/cia402Config.cmake.in"
  "${PROJECT_BINARY_DIR}/cia402Config.cmake"
  INSTALL_DESTINATION ${CIA402_INSTALL_CMAKEDIR})
write_basic_package_version_file(
  "${PROJECT_BINARY_DIR}/cia402ConfigVersion.cmake"
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMajorVersion)
install(FILES
  "${PROJECT_BINARY_DIR}/cia402Config.cmake"
  "${PROJECT_BINARY_DIR}/cia402ConfigVersion.cmake"
  DESTINATION ${CIA402_INSTALL_CMAKEDIR})

# pkg-config: relative to the .pc file's own folder, so `cmake --install --prefix ANYWHERE` works.
set(CIA402_PKGCONFIG_DIR "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(CIA402_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
  set(CIA402_PC_LIBDIR "${CMAKE_INSTALL_FULL_LIBDIR}")
  set(CIA402_PC_INCLUDEDIR "${CMAKE_INSTALL_FULL_INCLUDEDIR}")
else()
  file(RELATIVE_PATH cia402_pc_up "/${CIA402_PKGCONFIG_DIR}" "/")
  string(REGEX REPLACE "/$" "" cia402_pc_up "${cia402_pc_up}")
  set(CIA402_PC_PREFIX "\${pcfiledir}/${cia402_pc_up}")
  set(CIA402_PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
  set(CIA402_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
configure_file("${CMAKE_CURRENT_LIST_DIR}/cia402.pc.in" "${PROJECT_BINARY_DIR}/cia402.pc" @ONLY)
install(FILES "${PROJECT_BINARY_DIR}/cia402.pc" DESTINATION ${CIA402_PKGCONFIG_DIR})

if(TARGET cia402)
  install(TARGETS cia402 RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
