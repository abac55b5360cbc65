// SPDX-License-Identifier: MIT
// Injected on purpose by the symbol-check self test: float arithmetic on a core without
// an FPU must pull in soft-float helpers (__aeabi_fmul, __aeabi_i2f, ...).
int sl_inject_scale(int x, float k);
int sl_inject_scale(int x, float k) { return (int)((float)x * k); }
