# SPDX-License-Identifier: MIT
# test_pipeline_on_msg: the golden stream builder (tests/support/golden/sl_golden.c) is an extra source.
sl_add_unit_test(pipeline_on_msg SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/support/golden/sl_golden.c)
target_include_directories(test_pipeline_on_msg PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/support/golden)
