// SPDX-License-Identifier: MIT
// Board support (mps2.h): Arm semihosting (BKPT 0xAB; available on v6-M and v7-M) and SysTick.
#include "mps2.h"

#define SYST_CSR (*(volatile uint32_t *)0xE000E010U)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014U)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018U)

static uint32_t semihost(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm("r0") = op;
    register const void *r1 __asm("r1") = arg;
    __asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void mps2_write(const char *s)
{
    (void)semihost(0x04U, s); // SYS_WRITE0
}

void mps2_exit(int rc)
{
    // SYS_EXIT: ADP_Stopped_ApplicationExit (exit status 0) or RunTimeErrorUnknown (1).
    (void)semihost(0x18U, (const void *)(uintptr_t)(rc == 0 ? 0x20026U : 0x20023U));
    for (;;) {
    }
}

void mps2_systick_start(void)
{
    SYST_CSR = 0U;
    SYST_RVR = 0x00FFFFFFU;
    SYST_CVR = 0U;
    SYST_CSR = 0x5U; // enable, processor clock, no interrupt
}

uint32_t mps2_ticks(void)
{
    return 0x00FFFFFFU - SYST_CVR; // down-counter -> up-counter (24 bits)
}
