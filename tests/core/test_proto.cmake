# SPDX-License-Identifier: MIT
# test_proto: the golden stream builder (tests/support/golden/sl_golden.c) is an extra source.
sl_add_unit_test(proto SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/support/golden/sl_golden.c)
target_include_directories(test_proto PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/support/golden)
