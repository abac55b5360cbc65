# SPDX-License-Identifier: MIT
# test_assert: thresh.c compiled into the test with SL_ASSERT overridden through the user
# configuration header (tests/core/assert_user/sl_config_user.h, SL_CFG_USER_HEADER); the
# library's own thresh.c object is not linked (every symbol is defined by this copy).
sl_add_unit_test(assert SOURCES ${PROJECT_SOURCE_DIR}/firmware/core/thresh.c)
target_compile_definitions(test_assert PRIVATE SL_CFG_USER_HEADER)
target_include_directories(test_assert BEFORE PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/core/assert_user)
