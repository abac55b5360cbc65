// SPDX-License-Identifier: MIT
// Injected on purpose by the symbol-check self test: stdio in the core.
#include <stdio.h>
void sl_inject_log(int x);
void sl_inject_log(int x) { printf("%d\n", x); }
