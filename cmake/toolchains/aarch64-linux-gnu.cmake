# SPDX-License-Identifier: MIT
# aarch64 Linux (the usual companion computer); tests run under qemu-user with Debian's
# multiarch libc and cmocka (-L / : see shared TOOLCHAIN_NOTES).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64;-L;/)
set(SL_NM aarch64-linux-gnu-nm CACHE STRING "")
