# SPDX-License-Identifier: MIT
# test_thresh, plus test_thresh_swar32: the same tests against the 32-bit SWAR kernels
# (what a 32-bit MCU runs), compiled here on 64-bit hosts with SL_CFG_SWAR_BITS=32. The
# variant compiles thresh.c itself; sl_core's copy is then never pulled in.
sl_add_unit_test(thresh)
add_executable(test_thresh_swar32 ${CMAKE_CURRENT_SOURCE_DIR}/core/test_thresh.c
  ${PROJECT_SOURCE_DIR}/firmware/core/thresh.c)
target_compile_definitions(test_thresh_swar32 PRIVATE SL_CFG_SWAR_BITS=32)
set_target_properties(test_thresh_swar32 PROPERTIES C_STANDARD 11 C_EXTENSIONS OFF)
target_link_libraries(test_thresh_swar32 PRIVATE sl_core sl_test_support sl_host_warnings)
target_include_directories(test_thresh_swar32 PRIVATE ${PROJECT_SOURCE_DIR}/firmware/core)
add_test(NAME unit_thresh_swar32 COMMAND test_thresh_swar32)
set_tests_properties(unit_thresh_swar32 PROPERTIES LABELS "unit" TIMEOUT 300)
