# SPDX-License-Identifier: MIT
# SlPackage.cmake: Debian packages with CPack (`cpack -G DEB` in the build tree).
#   shadowlean-dev    the SDK: headers, libsl_core.a, CMake package, pkg-config (component sdk)
#   shadowleand       the daemon, its systemd unit, example config, DBCs (component daemon)
#   shadowlean-tools  the host tools and the Wireshark dissector (component tools)
#   python3-shadowlean  the Python package for CAN consumers (component python)
# Run-time dependencies come from dpkg-shlibdeps; the test tests/system/install/ builds, lists,
# unpacks and lints them.
set(CPACK_PACKAGE_NAME shadowlean)
set(CPACK_PACKAGE_VENDOR "The shadowlean authors")
set(CPACK_PACKAGE_CONTACT "The shadowlean authors <shadowlean@example.org>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Pole-lean warnings from a vehicle radar's chassis shadow (Navtech CTS350-X, CAN)")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_GENERATOR DEB)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_SET_DESTDIR ON) # the unit file's paths use the final prefix (SlInstall.cmake)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr) # with CPACK_SET_DESTDIR: the prefix the files are installed under
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_SDK_PACKAGE_NAME shadowlean-dev)
set(CPACK_DEBIAN_SDK_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DAEMON_PACKAGE_NAME shadowleand)
set(CPACK_DEBIAN_DAEMON_PACKAGE_SECTION net)
set(CPACK_DEBIAN_TOOLS_PACKAGE_NAME shadowlean-tools)
set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-shadowlean)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
set(CPACK_DEBIAN_PYTHON_PACKAGE_ARCHITECTURE all)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SHLIBDEPS OFF)
set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "python3:any, python3-canmatrix")
set(CPACK_DEBIAN_PYTHON_PACKAGE_RECOMMENDS "python3-can")
set(CPACK_COMPONENT_SDK_DESCRIPTION "shadowlean SDK: portable fixed-point core\n\
 The pole-lean core (C11, no allocation, no float, no OS) with its headers,\n\
 static library, CMake package and pkg-config file.")
set(CPACK_COMPONENT_DAEMON_DESCRIPTION "shadowlean daemon: radar TCP stream to CAN warnings\n\
 Reads a Navtech radar's stream and sends pole-lean warnings on CAN\n\
 (SocketCAN, candump log, gs_usb), with a systemd unit and the DBCs.")
set(CPACK_COMPONENT_TOOLS_DESCRIPTION "shadowlean host tools\n\
 Table generator, simulator, replay and record, inspector, viewer,\n\
 calibration, evaluation, benchmarks and a Wireshark dissector.")
set(CPACK_COMPONENT_PYTHON_DESCRIPTION "shadowlean CAN frames in Python: decode and verify\n\
 Decodes the CAN frames of a shadowlean module with the board's DBC\n\
 (canmatrix), verifies the E2E CRC and counters, reads candump logs and\n\
 live SocketCAN buses (python-can); python3 -m shadowlean.")
set(CPACK_COMPONENTS_ALL sdk daemon tools python)
include(CPack)
