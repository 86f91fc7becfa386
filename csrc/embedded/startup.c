/* startup.c: minimal Cortex-M start for the QEMU mps2 boards (an500 = M7,
 * an386 = M4F): vector table, FPU enable, .data copy, then newlib's
 * rdimon crt0 (_start zeroes .bss, sets up semihosting, calls main, exits
 * with its return value, which becomes QEMU's exit status). */
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _estack;
extern void _start(void);

void Reset_Handler(void);
void Fault_Handler(void);

__attribute__((section(".isr_vector"), used)) void (*const g_vectors[16])(void) = {
    (void (*)(void))(&_estack), Reset_Handler, Fault_Handler, Fault_Handler, Fault_Handler,
    Fault_Handler, Fault_Handler, 0, 0, 0, 0, Fault_Handler, Fault_Handler, 0, Fault_Handler,
    Fault_Handler,
};

void Reset_Handler(void) {
    /* enable CP10/CP11 (the FPU): hard-float code faults without it */
    volatile uint32_t *cpacr = (volatile uint32_t *)0xE000ED88u;
    *cpacr |= (0xFu << 20);
    __asm volatile("dsb\n isb");
    uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    _start();
    for (;;) {
    }
}

void Fault_Handler(void) {
    /* semihosting SYS_EXIT with ADP_Stopped_RunTimeErrorUnknown -> QEMU exits 1 */
    register uint32_t r0 __asm("r0") = 0x18u;
    register uint32_t r1 __asm("r1") = 0x20023u;
    __asm volatile("bkpt 0xAB" : : "r"(r0), "r"(r1));
    for (;;) {
    }
}
