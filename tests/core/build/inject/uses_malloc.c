// SPDX-License-Identifier: MIT
// Injected on purpose by the symbol-check self test: a core-like object that allocates.
#include <stdlib.h>
void *sl_inject_alloc(unsigned n);
void *sl_inject_alloc(unsigned n) { return malloc(n); }
