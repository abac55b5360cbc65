# SPDX-License-Identifier: MIT
# test_pipeline, plus test_pipeline_fw: the same tests against a core built in the firmware
# configuration (masked bins capped at 160, n <= 16: sizeof(sl_pipeline_t) <= 64 KiB is then
# a static_assert in sl_pipeline.h). The variant compiles every core source itself with the
# defines; only the board tables come from sl_core (they do not depend on these knobs).
sl_add_unit_test(pipeline)
file(GLOB _sl_core_srcs CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/firmware/core/*.c)
add_executable(test_pipeline_fw ${CMAKE_CURRENT_SOURCE_DIR}/core/test_pipeline.c ${_sl_core_srcs})
target_compile_definitions(test_pipeline_fw PRIVATE SL_CFG_MASK_BINS=160 SL_CFG_MASK_FRAMES_MAX=16)
set_target_properties(test_pipeline_fw PROPERTIES C_STANDARD 11 C_EXTENSIONS OFF)
target_link_libraries(test_pipeline_fw PRIVATE sl_core sl_test_support sl_host_warnings)
target_include_directories(test_pipeline_fw PRIVATE ${PROJECT_SOURCE_DIR}/firmware/core)
add_test(NAME unit_pipeline_fw COMMAND test_pipeline_fw)
set_tests_properties(unit_pipeline_fw PROPERTIES LABELS "unit" TIMEOUT 300)
