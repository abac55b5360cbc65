# SPDX-License-Identifier: MIT
# SlInstall.cmake: `cmake --install` and the Debian packages (CPack).
#
# What a user gets (GNUInstallDirs under the prefix, /usr for the .debs):
#   component sdk:    include/shadowlean/*.h (+ sl_version.h, boards/sl_board_<b>.h),
#                     lib/libsl_core.a (core + the configured boards' tables + registry),
#                     lib/cmake/shadowlean (find_package(shadowlean): shadowlean::core and
#                     shadowlean::board_<b>), lib/pkgconfig/shadowlean-core.pc
#   component daemon: sbin/shadowleand, lib/systemd/system/shadowleand.service,
#                     share/shadowlean/{shadowleand.conf,dbc/<board>.dbc,schema/targets.schema.json},
#                     man8 page
#   component tools:  bin/sl-* host tools, man1 pages, share/shadowlean/wireshark/{colossus,shadowlean_can}.lua,
#                     share/shadowlean/schema/{inspect,eval}.schema.json
#   component python: lib/python3/dist-packages/shadowlean (the CAN consumer package,
#                     python/; Debian's python3 path, as python3-* packages install it)
# Every component carries the licence (share/doc/<package>/copyright).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# ---- SDK: core library, headers, CMake package, pkg-config
set_target_properties(sl_core PROPERTIES EXPORT_NAME core)
add_library(shadowlean::core ALIAS sl_core)
install(TARGETS sl_core EXPORT shadowleanTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT sdk)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/shadowlean DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  COMPONENT sdk FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/include/shadowlean/sl_version.h
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/shadowlean COMPONENT sdk)
foreach(b ${SL_BOARDS})
  string(REPLACE "-" "_" c ${b})
  set(_h ${PROJECT_SOURCE_DIR}/boards/${b}/sl_board_${c}.h)
  if(NOT EXISTS ${_h})
    continue()
  endif()
  install(FILES ${_h} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/shadowlean/boards COMPONENT sdk)
  # shadowlean::board_<b>: the board's header (extern const sl_board_t sl_board_<b>) on top of
  # the core, whose archive holds the configured boards' tables.
  add_library(sl_board_${c} INTERFACE)
  set_target_properties(sl_board_${c} PROPERTIES EXPORT_NAME board_${c})
  target_include_directories(sl_board_${c} INTERFACE
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/boards/${b}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/shadowlean/boards>)
  target_link_libraries(sl_board_${c} INTERFACE sl_core)
  install(TARGETS sl_board_${c} EXPORT shadowleanTargets COMPONENT sdk)
endforeach()
install(EXPORT shadowleanTargets NAMESPACE shadowlean::
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/shadowlean COMPONENT sdk)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/shadowleanConfig.cmake.in
  ${PROJECT_BINARY_DIR}/shadowleanConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/shadowlean)
# 0.x: a minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/shadowleanConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/shadowleanConfig.cmake
  ${PROJECT_BINARY_DIR}/shadowleanConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/shadowlean COMPONENT sdk)
# pkg-config: prefix-relative, so a relocated install (cmake --install --prefix) works.
file(RELATIVE_PATH SL_PC_PREFIX_REL "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
configure_file(${PROJECT_SOURCE_DIR}/cmake/shadowlean-core.pc.in
  ${PROJECT_BINARY_DIR}/shadowlean-core.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/shadowlean-core.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT sdk)

# ---- daemon
if(TARGET shadowleand)
  install(TARGETS shadowleand RUNTIME DESTINATION ${CMAKE_INSTALL_SBINDIR} COMPONENT daemon)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/shadowleand.conf
    DESTINATION ${CMAKE_INSTALL_DATADIR}/shadowlean COMPONENT daemon)
  # The JSON Schema of --targets-out (docs/JSON_OUTPUTS.md).
  install(FILES ${PROJECT_SOURCE_DIR}/docs/schema/targets.schema.json
    DESTINATION ${CMAKE_INSTALL_DATADIR}/shadowlean/schema COMPONENT daemon)
  foreach(b ${SL_BOARDS})
    if(EXISTS ${PROJECT_SOURCE_DIR}/boards/${b}/shadowlean.dbc)
      install(FILES ${PROJECT_SOURCE_DIR}/boards/${b}/shadowlean.dbc
        DESTINATION ${CMAKE_INSTALL_DATADIR}/shadowlean/dbc RENAME ${b}.dbc COMPONENT daemon)
    endif()
  endforeach()
  # The unit names the installed daemon: paths follow the prefix given at install time.
  install(CODE "
    file(READ \"${PROJECT_SOURCE_DIR}/packaging/shadowleand.service\" _u)
    string(REPLACE \"/usr/local/sbin/\" \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_SBINDIR}/\" _u \"\${_u}\")
    string(REPLACE \"/usr/local/share/doc/shadowlean/\" \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_DATADIR}/doc/shadowleand/\" _u \"\${_u}\")
    set(_d \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/lib/systemd/system\")
    file(MAKE_DIRECTORY \"\${_d}\")
    file(WRITE \"\${_d}/shadowleand.service\" \"\${_u}\")
    message(STATUS \"Installing: \${_d}/shadowleand.service\")
  " COMPONENT daemon)
endif()

find_program(SL_GZIP gzip REQUIRED)

# ---- man pages, generated from each program's --help and --version (help2man, Debian)
find_program(SL_HELP2MAN help2man)
function(sl_man_page target section component description)
  if(NOT SL_HELP2MAN OR CMAKE_CROSSCOMPILING OR NOT TARGET ${target})
    return()
  endif()
  set(page ${PROJECT_BINARY_DIR}/man/man${section}/${target}.${section})
  set(out ${page}.gz) # compressed, as Debian policy wants (gzip -9n: reproducible)
  add_custom_command(OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/man/man${section}
    COMMAND ${SL_HELP2MAN} --no-info --no-discard-stderr --section=${section}
            --name=${description} --output=${page} $<TARGET_FILE:${target}>
    COMMAND ${SL_GZIP} -9nf ${page}
    DEPENDS ${target} VERBATIM)
  add_custom_target(man_${target} ALL DEPENDS ${out})
  install(FILES ${out} DESTINATION ${CMAKE_INSTALL_MANDIR}/man${section} COMPONENT ${component})
endfunction()
sl_man_page(shadowleand 8 daemon "pole-lean warnings on CAN from a Navtech radar's chassis shadow")
sl_man_page(sl-tables 1 tools "generate a board's C tables, DBC and plot from board.ini")
sl_man_page(sl-dbc 1 tools "write a board's CAN database (DBC) from the core's message layout")
sl_man_page(sl-alpha 1 tools "inclination from inner and outer range with the fixed-point estimator")
sl_man_page(sl-replay 1 tools "serve a capture as a Navtech radar, record a radar, convert captures")
sl_man_page(sl-inspect 1 tools "what a Navtech radar capture holds (text or JSON)")
sl_man_page(sl-sim 1 tools "simulate a radar scene with poles in the chassis shadow")
sl_man_page(sl-eval 1 tools "accuracy of the pole-lean estimate on simulated captures")
sl_man_page(sl-view 1 tools "draw what the module saw: scans, masks, detections")
sl_man_page(sl-calib 1 tools "measure the chassis shadow and the range elongation")
sl_man_page(sl-bench 1 tools "instruction counts and memory of the detection pipeline")
sl_man_page(sl-bench-proto 1 tools "instruction counts of the stream decoder")
sl_man_page(sl-bench-junk 1 tools "decoder cost per byte of junk input")
sl_man_page(sl-gsusb-send 1 tools "send CAN frames through a gs_usb/candleLight adapter")

# ---- host tools
foreach(t sl-tables sl-dbc sl-alpha sl-replay sl-inspect sl-sim sl-eval sl-view sl-calib
          sl-bench sl-bench-proto sl-bench-junk sl-gsusb-send)
  if(TARGET ${t})
    install(TARGETS ${t} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tools)
  endif()
endforeach()
if(SL_BUILD_HOST_TOOLS)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/wireshark/colossus.lua
    ${PROJECT_SOURCE_DIR}/packaging/wireshark/shadowlean_can.lua
    DESTINATION ${CMAKE_INSTALL_DATADIR}/shadowlean/wireshark COMPONENT tools)
  install(FILES ${PROJECT_SOURCE_DIR}/docs/schema/inspect.schema.json
    ${PROJECT_SOURCE_DIR}/docs/schema/eval.schema.json
    DESTINATION ${CMAKE_INSTALL_DATADIR}/shadowlean/schema COMPONENT tools)
endif()

# ---- Python package for CAN consumers (python/shadowlean): pure Python, Debian's path.
# _version.py is written with the project's version baked in (the source tree's copy reads
# it from CMakeLists.txt, which is not installed).
set(SL_PYTHON_DIR lib/python3/dist-packages CACHE STRING
    "Where the Python package is installed, relative to the prefix (Debian: lib/python3/dist-packages)")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/python/shadowlean DESTINATION ${SL_PYTHON_DIR}
  COMPONENT python PATTERN "__pycache__" EXCLUDE PATTERN "*.pyc" EXCLUDE PATTERN "_version.py" EXCLUDE)
file(WRITE ${PROJECT_BINARY_DIR}/python/_version.py
  "# SPDX-License-Identifier: MIT\n\"\"\"The package version (written by cmake --install).\"\"\"\n__version__ = \"${PROJECT_VERSION}\"\n")
install(FILES ${PROJECT_BINARY_DIR}/python/_version.py DESTINATION ${SL_PYTHON_DIR}/shadowlean
  COMPONENT python)

# The Debian changelog, compressed as policy wants it (gzip -9n: reproducible).
add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/changelog.gz
  COMMAND ${SL_GZIP} -9nc ${PROJECT_SOURCE_DIR}/packaging/debian/changelog > ${PROJECT_BINARY_DIR}/changelog.gz
  DEPENDS ${PROJECT_SOURCE_DIR}/packaging/debian/changelog VERBATIM)
add_custom_target(sl_changelog ALL DEPENDS ${PROJECT_BINARY_DIR}/changelog.gz)

# ---- licence and README in every component's doc folder (Debian: copyright)
# (doc folder = the Debian package's name, cmake/SlPackage.cmake)
foreach(pair "sdk:shadowlean-dev" "daemon:shadowleand" "tools:shadowlean-tools"
             "python:python3-shadowlean")
  string(REPLACE ":" ";" pair ${pair})
  list(GET pair 0 comp)
  list(GET pair 1 pkg)
  install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/${pkg}
    RENAME copyright COMPONENT ${comp})
  install(FILES ${PROJECT_BINARY_DIR}/changelog.gz DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/${pkg}
    COMPONENT ${comp})
endforeach()
install(FILES ${PROJECT_SOURCE_DIR}/README.md
  DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/shadowleand COMPONENT daemon)
