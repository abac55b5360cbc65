// SPDX-License-Identifier: MIT
// Injected on purpose by the VFP check's self test: compiled for the hard-float ABI without
// -mgeneral-regs-only, float arithmetic and a 64-bit value live in VFP registers.
#include <stdint.h>
float sl_inject_vfp_scale(float x, float k);
float sl_inject_vfp_scale(float x, float k) { return x * k + 1.0f; }
