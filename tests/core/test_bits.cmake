# SPDX-License-Identifier: MIT
# test_bits, plus test_bits_table: the same tests with SL_NO_INTRINSICS, i.e. the portable
# de Bruijn count of trailing zeros (what ARMv6-M runs) on every host.
sl_add_unit_test(bits)
add_executable(test_bits_table ${CMAKE_CURRENT_SOURCE_DIR}/core/test_bits.c)
target_compile_definitions(test_bits_table PRIVATE SL_NO_INTRINSICS)
set_target_properties(test_bits_table PROPERTIES C_STANDARD 11 C_EXTENSIONS OFF)
target_link_libraries(test_bits_table PRIVATE sl_test_support sl_host_warnings)
target_include_directories(test_bits_table PRIVATE ${PROJECT_SOURCE_DIR}/firmware/core)
add_test(NAME unit_bits_table COMMAND test_bits_table)
set_tests_properties(unit_bits_table PROPERTIES LABELS "unit" TIMEOUT 300)
