/* SPDX-License-Identifier: MIT */
/* mps2_calib_loop(n): exactly 2 n instructions (subs + bne per iteration) + bx lr, the
   reference the SysTick instruction counter is calibrated against (main.c). Valid
   for ARMv6-M and ARMv7-M. */
    .syntax unified
    .thumb
    .text
    .global mps2_calib_loop
    .type mps2_calib_loop, %function
    .thumb_func
mps2_calib_loop:
1:  subs r0, r0, #1
    bne 1b
    bx lr
    .size mps2_calib_loop, . - mps2_calib_loop
