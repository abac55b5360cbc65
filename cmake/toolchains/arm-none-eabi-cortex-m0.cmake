# Bare-metal Cortex-M0 (ARMv6-M, no FPU): any float in the core shows up as __aeabi_f*/d*.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m0 -mthumb -ffunction-sections -fdata-sections -fstack-usage")
set(SL_NM arm-none-eabi-nm CACHE STRING "")
set(SL_SIZE arm-none-eabi-size CACHE STRING "")
