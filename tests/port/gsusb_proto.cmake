# SPDX-License-Identifier: MIT
# unit_gsusb_proto: the gs_usb protocol layer (firmware/port/linux/gsusb/gsusb_proto.c, no
# libusb) against the in-process fake candleLight (tests/system/gsusb/gsusb_fake.c).
# A port module's test, but included by tests/CMakeLists.txt even where the port library is
# not built (cross-s390x): it needs only these two sources, and the big-endian run is the
# check that the wire structs are little-endian whatever the host.
add_executable(test_gsusb_proto ${CMAKE_CURRENT_LIST_DIR}/test_gsusb_proto.c
  ${PROJECT_SOURCE_DIR}/firmware/port/linux/gsusb/gsusb_proto.c
  ${PROJECT_SOURCE_DIR}/tests/system/gsusb/gsusb_fake.c)
set_target_properties(test_gsusb_proto PROPERTIES C_STANDARD 11 C_EXTENSIONS OFF)
target_include_directories(test_gsusb_proto PRIVATE
  ${PROJECT_SOURCE_DIR}/firmware/port/linux ${PROJECT_SOURCE_DIR}/tests/system/gsusb)
target_link_libraries(test_gsusb_proto PRIVATE sl_core sl_test_support sl_host_warnings)
add_test(NAME unit_gsusb_proto COMMAND test_gsusb_proto)
set_tests_properties(unit_gsusb_proto PROPERTIES LABELS "unit;port;gsusb" TIMEOUT 300)
