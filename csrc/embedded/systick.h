/* systick.h: instruction counting on the QEMU mps2 boards, shared by the
 * bench images (bench_main.c, ops_main.c).
 *
 * QEMU does not model the DWT cycle counter, but with -icount shift=N its
 * virtual clock advances 2^N ns per guest instruction, and SysTick
 * (processor clock) counts that clock: one count per a fixed number of
 * instructions, which systick_calibrate measures on 4 x 1024 NOPs. */
#ifndef PYINS_SYSTICK_H
#define PYINS_SYSTICK_H

#include <stdint.h>
#include <stdio.h>

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

/* counts between two readings of the 24-bit down-counter */
static inline uint32_t elapsed(uint32_t t0, uint32_t t1) { return (t0 - t1) & 0xFFFFFFu; }

#define NOP8 "nop\n nop\n nop\n nop\n nop\n nop\n nop\n nop\n"
#define NOP64 NOP8 NOP8 NOP8 NOP8 NOP8 NOP8 NOP8 NOP8

/* Start SysTick free-running, time the reading itself (the least of 16)
 * and 4 blocks of 1024 NOPs, and print "CAL nops 4096 counts <n> empty <e>"
 * (tools/size_report.py and tools/m4f_ops.py read it). */
static inline void systick_calibrate(uint32_t *nops, uint32_t *empty) {
    uint32_t t0, t1;
    int k;
    SYST_RVR = 0xFFFFFFu;
    SYST_CVR = 0u;
    SYST_CSR = 5u; /* enable, processor clock, no interrupt */
    *empty = 0xFFFFFFu;
    *nops = 0u;
    for (k = 0; k < 16; ++k) {
        t0 = SYST_CVR;
        t1 = SYST_CVR;
        if (elapsed(t0, t1) < *empty) *empty = elapsed(t0, t1);
    }
    for (k = 0; k < 4; ++k) {
        t0 = SYST_CVR;
        __asm volatile(NOP64 NOP64 NOP64 NOP64 NOP64 NOP64 NOP64 NOP64
                       NOP64 NOP64 NOP64 NOP64 NOP64 NOP64 NOP64 NOP64);
        t1 = SYST_CVR;
        *nops += elapsed(t0, t1);
    }
    printf("CAL nops %d counts %lu empty %lu\n", 4 * 1024, (unsigned long)*nops, (unsigned long)*empty);
}

#endif
