/* ops_main.c: where the Cortex-M4F's instructions go in a navigation tick.
 *
 * The M4F's FPU is single precision: every double operation of the core is
 * a call into libgcc's soft-float routines (__aeabi_dmul, __aeabi_dadd, ...)
 * or newlib's sqrt. This image (built for cortex-m4 only, linked with
 * -Wl,--wrap for each of those routines, see CMakeLists.txt) counts the
 * calls that one navigation tick without a record makes (pyins_run with
 * outputs NULL, bench_modes.h's "nav" scenario), and measures what each
 * routine costs on typical operands, with SysTick under QEMU -icount as
 * bench_main.c does. tools/m4f_ops.py runs it and prints the table:
 *   CAL nops <instructions> counts <counts> empty <counts>
 *   OP <name> counts <counts per OP_REPEAT calls, loop included>
 *   NAV ticks <n> counts <counts>
 *   CALLS <name> <calls> ...
 *   DONE
 * The wrappers add a few instructions to each call; they are in both the
 * per-call cost and the tick, so the split adds up. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "arm_softfp.h"
#include "bench_modes.h"
#include "pyins_core.h"
#include "systick.h"

#define OP_REPEAT 1000
#define NAV_TICKS 3000

static unsigned char g_mem[20480] __attribute__((aligned(16)));
static volatile int g_counting;

/* libgcc's routines take and return doubles in core registers (base AAPCS)
 * whatever the float ABI of their callers. */
#define AAPCS __attribute__((pcs("aapcs")))
#define WRAP2(name, ret)                                                           \
    static unsigned long n_##name;                                                 \
    AAPCS ret __real___aeabi_##name(double, double);                              \
    AAPCS ret __wrap___aeabi_##name(double a, double b) {                         \
        n_##name += (unsigned long)g_counting;                                     \
        return __real___aeabi_##name(a, b);                                       \
    }
WRAP2(dmul, double)
WRAP2(ddiv, double)
/* addition and subtraction: the core's own route (csrc/port/arm_softfp_add.c,
 * which the pyins_core target wraps them with), counted */
#define WRAP_ADD(name)                                                             \
    static unsigned long n_##name;                                                 \
    AAPCS double __wrap___aeabi_##name(double a, double b) {                      \
        n_##name += (unsigned long)g_counting;                                     \
        return pyins_softfp_##name(a, b);                                         \
    }
WRAP_ADD(dadd)
WRAP_ADD(dsub)
WRAP_ADD(drsub)
WRAP2(dcmplt, int)
WRAP2(dcmple, int)
WRAP2(dcmpgt, int)
WRAP2(dcmpge, int)
WRAP2(dcmpeq, int)
WRAP2(dcmpun, int)
static unsigned long n_sqrt;
double __real_sqrt(double);
double __wrap_sqrt(double x) {
    n_sqrt += (unsigned long)g_counting;
    return __real_sqrt(x);
}

static volatile double g_a = 1.2345678901234567, g_b = 0.98765432109876543, g_sink;

/* OP_REPEAT evaluations of expr on operands loaded from memory each time */
#define TIME(label, expr)                                   \
    do {                                                    \
        uint32_t t0, t1;                                    \
        int k;                                              \
        t0 = SYST_CVR;                                      \
        for (k = 0; k < OP_REPEAT; ++k) {                   \
            const double a = g_a, b = g_b;                  \
            (void)b; /* both volatile loads in every loop */ \
            g_sink = (expr);                                \
        }                                                   \
        t1 = SYST_CVR;                                      \
        printf("OP %s counts %lu\n", label, (unsigned long)elapsed(t0, t1)); \
    } while (0)

int main(void) {
    pyins_config cfg;
    pyins_sample s;
    pyins_output out;
    uint32_t t0, t1, nops, empty, sum = 0;
    long i;
    int m;
    systick_calibrate(&nops, &empty);
    TIME("loop", a);
    TIME("dmul", a * b);
    TIME("dadd", a + b);
    TIME("dsub", a - b);
    TIME("ddiv", a / b);
    TIME("sqrt", sqrt(a));
    TIME("dcmp", (double)(a < b));

    m = bench_mode_of("nav");
    if (bench_config(m, NAV_TICKS, &cfg) != 0 || pyins_init(g_mem, sizeof g_mem, &cfg) != PYINS_OK) {
        printf("FAIL init\n");
        return 3;
    }
    memset(&out, 0, sizeof out);
    for (i = 0; i < NAV_TICKS; ++i) {
        bench_sample(m, i, out.table_angle_cmd_rad, &s);
        g_counting = 1;
        t0 = SYST_CVR;
        if (pyins_run((pyins_core *)g_mem, &s, 1, NULL, NULL) != PYINS_OK) {
            printf("FAIL step %ld\n", i);
            return 4;
        }
        t1 = SYST_CVR;
        g_counting = 0;
        sum += elapsed(t0, t1);
        pyins_get_output((const pyins_core *)g_mem, &out);   /* the encoder reads the command back */
    }
    printf("NAV ticks %d counts %lu\n", NAV_TICKS, (unsigned long)sum);
    printf("CALLS dmul %lu dadd %lu dsub %lu drsub %lu ddiv %lu sqrt %lu dcmp %lu\n", n_dmul, n_dadd, n_dsub,
           n_drsub, n_ddiv, n_sqrt, n_dcmplt + n_dcmple + n_dcmpgt + n_dcmpge + n_dcmpeq + n_dcmpun);
    printf("DONE\n");
    return 0;
}
