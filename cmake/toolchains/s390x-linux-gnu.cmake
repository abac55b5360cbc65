# SPDX-License-Identifier: MIT
# s390x Linux: the big-endian target Debian 12 still ships; catches wire-endianness bugs.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR s390x)
set(CMAKE_C_COMPILER s390x-linux-gnu-gcc)
set(CMAKE_LIBRARY_ARCHITECTURE s390x-linux-gnu)
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-s390x;-L;/)
set(SL_NM s390x-linux-gnu-nm CACHE STRING "")
