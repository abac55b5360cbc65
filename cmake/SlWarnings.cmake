# SPDX-License-Identifier: MIT
# Warning sets, applied per target (never globally).
add_library(sl_warnings INTERFACE)
target_compile_options(sl_warnings INTERFACE
  $<$<COMPILE_LANGUAGE:C>:-Wall -Wextra -pedantic -Wconversion -Wsign-conversion
    -Wdouble-promotion -Wfloat-equal -Wcast-align -Wundef -Wswitch-enum
    -Wmissing-prototypes -Wstrict-prototypes -Wshadow>
  $<$<BOOL:${SL_WERROR}>:-Werror>)

# Looser set for host tools (C++17) and test programs: still -Wall -Wextra -Werror.
add_library(sl_host_warnings INTERFACE)
target_compile_options(sl_host_warnings INTERFACE -Wall -Wextra
  $<$<BOOL:${SL_WERROR}>:-Werror>)
