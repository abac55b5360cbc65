# Bare-metal Cortex-M4F (ARMv7E-M, single-precision FPU, hard-float ABI).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_C_FLAGS_INIT "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -ffunction-sections -fdata-sections -fstack-usage")
set(SL_NM arm-none-eabi-nm CACHE STRING "")
set(SL_SIZE arm-none-eabi-size CACHE STRING "")
