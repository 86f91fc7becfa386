/* bench_main.c: instructions per pyins_step in each mode on Cortex-M, under
 * QEMU with -icount (tools/size_report.py runs it).
 *
 * QEMU does not model the DWT cycle counter (CYCCNT reads 0), but with
 * -icount shift=N its virtual clock advances 2^N ns per guest instruction,
 * and SysTick (processor clock, 25 MHz on the mps2 boards) counts that
 * clock. So SysTick counts instructions: one count per 40 / 2^N of them. The
 * image measures that ratio itself (a block of 1024 NOPs) and the cost of
 * reading the counter, then times every pyins_step of each mode of
 * bench_modes.h (the scenarios of tools/bench_step.c on the host):
 *   CAL nops <instructions> counts <counts> empty <counts>
 *   MODE <name> ticks <n> sum <counts> max <counts> maxtick <k>
 *   DONE
 * These are instruction counts, not cycles: QEMU has no pipeline model. */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "bench_modes.h"
#include "pyins_core.h"
#include "systick.h"

#ifndef BENCH_TICKS
#define BENCH_TICKS 3000
#endif

static unsigned char g_mem[20480] __attribute__((aligned(16)));

int main(void) {
    pyins_config cfg;
    pyins_sample s;
    pyins_output out;
    uint32_t t0, t1, empty, nops;
    int m, k;
    /* calibration: the reading itself, and 1024 instructions */
    systick_calibrate(&nops, &empty);

    if (pyins_core_size() > sizeof g_mem) {
        printf("FAIL instance too large\n");
        return 2;
    }
    for (m = 0; m < BENCH_N_MODES; ++m) {
        uint32_t sum = 0, worst = 0;
        long i, worst_tick = -1;
        if (bench_config(m, BENCH_TICKS, &cfg) != 0 || pyins_init(g_mem, sizeof g_mem, &cfg) != PYINS_OK) {
            printf("FAIL init %s\n", bench_mode_name[m]);
            return 3;
        }
        memset(&out, 0, sizeof out);
        for (i = 0; i < BENCH_TICKS; ++i) {
            uint32_t c;
            int st;
            pyins_ref refs[2];
            const int n_refs = bench_refs(m, i, refs);
            int r;
            for (r = 0; r < n_refs; ++r) {
                if (pyins_push_ref((pyins_core *)g_mem, &refs[r]) != PYINS_OK) {
                    printf("FAIL push %s %ld\n", bench_mode_name[m], i);
                    return 5;
                }
            }
            bench_sample(m, i, out.table_angle_cmd_rad, &s);
            t0 = SYST_CVR;
            st = pyins_step((pyins_core *)g_mem, &s, &out);
            t1 = SYST_CVR;
            if (st != PYINS_OK) {
                printf("FAIL step %s %ld %d\n", bench_mode_name[m], i, st);
                return 4;
            }
            c = elapsed(t0, t1);
            sum += c;
            if (c > worst) {
                worst = c;
                worst_tick = i;
            }
        }
        printf("MODE %s ticks %d sum %lu max %lu maxtick %ld mode %ld nav_mode %ld used %lu/%lu/%lu\n",
               bench_mode_name[m], BENCH_TICKS, (unsigned long)sum, (unsigned long)worst, worst_tick,
               (long)out.mode, (long)out.nav_mode, (unsigned long)out.n_ref_used[0],
               (unsigned long)out.n_ref_used[1], (unsigned long)out.n_ref_used[2]);
    }
    /* The navigation scenario again, as a firmware that reads the motor
     * command every tick takes it: no record (pyins_run with outputs NULL,
     * the command from pyins_get_motor_command outside the count), and a
     * compact record every tick (pyins_run_nav). */
    for (k = 0; k < 2; ++k) {
        uint32_t sum = 0, worst = 0;
        long i, worst_tick = -1;
        double cmd = 0.0;
        m = bench_mode_of("nav");
        if (bench_config(m, BENCH_TICKS, &cfg) != 0 || pyins_init(g_mem, sizeof g_mem, &cfg) != PYINS_OK) {
            printf("FAIL init nav (%s)\n", k == 0 ? "null" : "compact");
            return 3;
        }
        for (i = 0; i < BENCH_TICKS; ++i) {
            pyins_nav nav[2];   /* the capacity a call of n samples needs: n / every + 1 */
            pyins_motor_command mc;
            size_t done = 0, n_out = 0;
            uint32_t c;
            int st;
            bench_sample(m, i, cmd, &s);
            t0 = SYST_CVR;
            st = k == 0 ? pyins_run((pyins_core *)g_mem, &s, 1, NULL, NULL)
                        : pyins_run_nav((pyins_core *)g_mem, &s, 1, 1, nav, 2, &done, &n_out);
            t1 = SYST_CVR;
            if (st != PYINS_OK) {
                printf("FAIL step nav (%s) %ld %d\n", k == 0 ? "null" : "compact", i, st);
                return 4;
            }
            if (k == 0) {
                pyins_get_motor_command((const pyins_core *)g_mem, &mc);
                cmd = mc.angle_rad;
            } else {
                cmd = nav[0].table_angle_cmd_rad;
            }
            c = elapsed(t0, t1);
            sum += c;
            if (c > worst) {
                worst = c;
                worst_tick = i;
            }
        }
        printf("MODE %s ticks %d sum %lu max %lu maxtick %ld\n", k == 0 ? "nav_null" : "nav_compact",
               BENCH_TICKS, (unsigned long)sum, (unsigned long)worst, worst_tick);
    }
    printf("DONE\n");
    return 0;
}
