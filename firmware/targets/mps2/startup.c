// SPDX-License-Identifier: MIT
// Startup for the Arm MPS2 FPGA boards as QEMU models them (mps2-an385: Cortex-M3,
// mps2-an386: Cortex-M4): vector table, reset handler (copy .data, zero .bss, paint the
// stack for the high-water measurement), fault handlers that report over semihosting.
// The FPU of the M4 is deliberately left OFF (CPACR as at reset): the core must run without
// it (-mgeneral-regs-only); any VFP instruction would end in the UsageFault below.
#include <stdint.h>
#include <string.h>

#include "mps2.h"

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _sstack, _estack;
extern int main(void);

void Reset_Handler(void);
void Fault_Handler(void);
void Default_Handler(void);

void Reset_Handler(void)
{
    memcpy(&_sdata, &_sidata, (size_t)((uintptr_t)&_edata - (uintptr_t)&_sdata));
    memset(&_sbss, 0, (size_t)((uintptr_t)&_ebss - (uintptr_t)&_sbss));
    // Paint the stack below this frame (the reset handler's own few words stay above).
    volatile uint32_t *p = &_sstack;
    uint32_t sp;
    __asm volatile("mov %0, sp" : "=r"(sp));
    while ((uintptr_t)p < sp - 64U) {
        *p++ = MPS2_STACK_PAINT;
    }
    const int rc = main();
    mps2_exit(rc);
}

void Fault_Handler(void)
{
    mps2_write("FAULT: HardFault/UsageFault (FPU off? stack overflow?)\n");
    mps2_exit(2);
}

void Default_Handler(void)
{
    mps2_write("FAULT: unexpected exception\n");
    mps2_exit(3);
}

typedef void (*vector_t)(void);
__attribute__((section(".isr_vector"), used)) static const vector_t vectors[16] = {
    (vector_t)(uintptr_t)&_estack, // initial SP
    Reset_Handler,
    Default_Handler, // NMI
    Fault_Handler,   // HardFault
    Fault_Handler,   // MemManage
    Fault_Handler,   // BusFault
    Fault_Handler,   // UsageFault (an FP instruction with CP10/CP11 off on v7-M)
    0, 0, 0, 0,
    Default_Handler, // SVCall
    Default_Handler, // DebugMon
    0,
    Default_Handler, // PendSV
    Default_Handler, // SysTick (not enabled: SysTick is polled)
};
