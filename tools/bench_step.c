/* bench_step.c: drive the firmware for instruction counting.
 *   valgrind --tool=callgrind --toggle-collect=pyins_step ./bench_step 10000 [MODE]
 * counts the instructions inside pyins_step only (repeatable, unlike time).
 * MODE: nav (default), coarse, fine5, fine8: every step in that mode.
 * tools/bench_strapdown.py and tools/bench_alignment.py run this. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pyins_core.h"

int main(int argc, char **argv) {
    const long n = argc > 1 ? atol(argv[1]) : 10000;
    const char *mode = argc > 2 ? argv[2] : "nav";
    static unsigned char mem[1 << 14] __attribute__((aligned(64)));
    pyins_config cfg;
    pyins_sample s;
    pyins_output out;
    long i;
    if (pyins_core_size() > sizeof mem) {
        fprintf(stderr, "instance larger than the static buffer\n");
        return 2;
    }
    pyins_config_default(&cfg);
    cfg.lat_rad = 0.6;
    cfg.euler_b_rad[0] = 0.02;
    cfg.euler_b_rad[1] = -0.03;
    cfg.euler_b_rad[2] = 1.0;
    if (strcmp(mode, "coarse") == 0) {
        cfg.coarse_ticks = 25500;           /* the longest the storage allows at 1 s outputs */
        if (n > cfg.coarse_ticks) return 5;
    } else if (strcmp(mode, "fine5") == 0 || strcmp(mode, "fine8") == 0) {
        cfg.fine_ticks = (int32_t)n + 1;
        cfg.fine_states = mode[4] == '8' ? 8 : 5;
    } else if (strcmp(mode, "nav") != 0) {
        fprintf(stderr, "unknown mode %s\n", mode);
        return 2;
    }
    if (pyins_init(mem, sizeof mem, &cfg) != PYINS_OK) return 3;
    memset(&s, 0, sizeof s);
    for (i = 0; i < n; ++i) {
        /* a gently swinging IMU, so every branch of a moving step runs */
        s.dtheta_p_rad[0] = 1e-4 * (double)((i % 200) - 100) / 100.0;
        s.dtheta_p_rad[1] = 5e-7 + 5e-5 * (double)((i % 300) - 150) / 150.0;
        s.dtheta_p_rad[2] = 3e-7;
        s.dv_p_mps[0] = 1e-3;
        s.dv_p_mps[1] = -2e-3;
        s.dv_p_mps[2] = 0.0978;
        s.table_angle_rad = 0.0;
        if (pyins_step((pyins_core *)mem, &s, &out) != PYINS_OK) return 4;
    }
    printf("ticks %ld lat %.17g\n", n, out.lat_rad);
    return 0;
}
