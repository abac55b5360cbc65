# SPDX-License-Identifier: MIT
# test_mask, plus test_mask_swar32: the same tests against the 32-bit lane kernels (what a
# 32-bit MCU runs), compiled here with SL_CFG_SWAR_BITS=32 (see test_thresh.cmake).
sl_add_unit_test(mask)
add_executable(test_mask_swar32 ${CMAKE_CURRENT_SOURCE_DIR}/core/test_mask.c
  ${PROJECT_SOURCE_DIR}/firmware/core/mask.c)
target_compile_definitions(test_mask_swar32 PRIVATE SL_CFG_SWAR_BITS=32)
set_target_properties(test_mask_swar32 PROPERTIES C_STANDARD 11 C_EXTENSIONS OFF)
target_link_libraries(test_mask_swar32 PRIVATE sl_core sl_test_support sl_host_warnings)
target_include_directories(test_mask_swar32 PRIVATE ${PROJECT_SOURCE_DIR}/firmware/core)
add_test(NAME unit_mask_swar32 COMMAND test_mask_swar32)
set_tests_properties(unit_mask_swar32 PROPERTIES LABELS "unit" TIMEOUT 300)
# test_mask_fw: the same tests with the firmware capacities (160-bin mask rows, n <= 16).
add_executable(test_mask_fw ${CMAKE_CURRENT_SOURCE_DIR}/core/test_mask.c
  ${PROJECT_SOURCE_DIR}/firmware/core/mask.c)
target_compile_definitions(test_mask_fw PRIVATE SL_CFG_MASK_BINS=160 SL_CFG_MASK_FRAMES_MAX=16)
set_target_properties(test_mask_fw PROPERTIES C_STANDARD 11 C_EXTENSIONS OFF)
target_link_libraries(test_mask_fw PRIVATE sl_core sl_test_support sl_host_warnings)
target_include_directories(test_mask_fw PRIVATE ${PROJECT_SOURCE_DIR}/firmware/core)
add_test(NAME unit_mask_fw COMMAND test_mask_fw)
set_tests_properties(unit_mask_fw PROPERTIES LABELS "unit" TIMEOUT 300)
