# SPDX-License-Identifier: MIT
# Bare-metal Cortex-M4F (ARMv7E-M, single-precision FPU, hard-float ABI).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -ffunction-sections -fdata-sections -fstack-usage")
set(SL_NM arm-none-eabi-nm CACHE STRING "")
set(SL_SIZE arm-none-eabi-size CACHE STRING "")
# Example firmware (firmware/targets): CPU name in its report, QEMU machine that runs it
# (mps2-an385 is a Cortex-M3: QEMU has no Cortex-M0 board; ARMv6-M code runs on it unchanged).
set(SL_FW_CPU cortex-m4 CACHE STRING "")
set(SL_FW_MACHINE mps2-an386 CACHE STRING "")
set(SL_CPU_TAG cortex-m4f CACHE STRING "CPU column of firmware/size_budget.txt")
