# SPDX-License-Identifier: MIT
# test_gsusb_proto: the gs_usb protocol layer (firmware/port/linux/gsusb/gsusb_proto.c, no libusb)
# and the in-process fake candleLight (tests/system/gsusb/gsusb_fake.c). Only these two extra
# sources, so the test also builds for the cross presets (aarch64, big-endian s390x).
sl_add_unit_test(gsusb_proto SOURCES
  ${PROJECT_SOURCE_DIR}/firmware/port/linux/gsusb/gsusb_proto.c
  ${CMAKE_CURRENT_SOURCE_DIR}/system/gsusb/gsusb_fake.c)
target_include_directories(test_gsusb_proto PRIVATE
  ${PROJECT_SOURCE_DIR}/firmware/port/linux ${CMAKE_CURRENT_SOURCE_DIR}/system/gsusb)
