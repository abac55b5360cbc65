# SPDX-License-Identifier: MIT
# Bare-metal Cortex-M0 (ARMv6-M, no FPU): any float in the core shows up as __aeabi_f*/d*.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m0 -mthumb -ffunction-sections -fdata-sections -fstack-usage")
set(SL_NM arm-none-eabi-nm CACHE STRING "")
set(SL_SIZE arm-none-eabi-size CACHE STRING "")
# Example firmware (firmware/targets): CPU name in its report, QEMU machine that runs it
# (mps2-an385 is a Cortex-M3: QEMU has no Cortex-M0 board; ARMv6-M code runs on it unchanged).
set(SL_FW_CPU cortex-m0 CACHE STRING "")
set(SL_FW_MACHINE mps2-an385 CACHE STRING "")
set(SL_CPU_TAG cortex-m0 CACHE STRING "CPU column of firmware/size_budget.txt")
