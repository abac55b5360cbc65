// SPDX-License-Identifier: MIT
// Board support for the example firmware on QEMU's MPS2 models: semihosting output and exit,
// SysTick as an instruction counter (with -icount shift=0 one instruction = 1 ns of
// virtual time; SysTick counts the 25 MHz CPU clock, i.e. one tick per 40 instructions,
// calibrated at run time against a loop of known length).
#ifndef SHADOWLEAN_MPS2_H
#define SHADOWLEAN_MPS2_H

#include <stdint.h>

#define MPS2_STACK_PAINT 0xA5A5A5A5U

void mps2_write(const char *s);
__attribute__((noreturn)) void mps2_exit(int rc);
void mps2_systick_start(void);
uint32_t mps2_ticks(void);

#endif
