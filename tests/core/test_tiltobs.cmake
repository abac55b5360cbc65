# SPDX-License-Identifier: MIT
# test_tiltobs, plus test_tiltobs_fw: the same tests with the firmware capacities (masked bins
# 160: 4 rings of 16 observations, sl_config.h).
sl_add_unit_test(tiltobs)
file(GLOB _sl_core_srcs CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/firmware/core/*.c)
add_executable(test_tiltobs_fw ${CMAKE_CURRENT_SOURCE_DIR}/core/test_tiltobs.c ${_sl_core_srcs})
target_compile_definitions(test_tiltobs_fw PRIVATE SL_CFG_MASK_BINS=160 SL_CFG_MASK_FRAMES_MAX=16)
set_target_properties(test_tiltobs_fw PROPERTIES C_STANDARD 11 C_EXTENSIONS OFF)
target_link_libraries(test_tiltobs_fw PRIVATE sl_core sl_test_support sl_host_warnings)
target_include_directories(test_tiltobs_fw PRIVATE ${PROJECT_SOURCE_DIR}/firmware/core)
add_test(NAME unit_tiltobs_fw COMMAND test_tiltobs_fw)
set_tests_properties(unit_tiltobs_fw PROPERTIES LABELS "unit" TIMEOUT 300)
