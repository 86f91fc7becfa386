/* bench_step.c: drive the firmware for instruction counting.
 *   valgrind --tool=callgrind --toggle-collect=pyins_step ./bench_step 10000 [MODE]
 * counts the instructions inside pyins_step only (repeatable, unlike time).
 * MODE: nav (default), navix, coarse, fine5, fine8: every step in that mode
 * (csrc/embedded/bench_modes.h: the same scenarios as the Cortex-M bench
 * image). tools/bench_strapdown.py, tools/bench_alignment.py and
 * tools/size_report.py run this. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_modes.h"
#include "pyins_core.h"

int main(int argc, char **argv) {
    const long n = argc > 1 ? atol(argv[1]) : 10000;
    const char *name = argc > 2 ? argv[2] : "nav";
    const int mode = bench_mode_of(name);
    static unsigned char mem[1 << 14] __attribute__((aligned(64)));
    pyins_config cfg;
    pyins_sample s;
    pyins_output out;
    long i;
    if (pyins_core_size() > sizeof mem) {
        fprintf(stderr, "instance larger than the static buffer\n");
        return 2;
    }
    if (mode < 0) {
        fprintf(stderr, "unknown mode %s\n", name);
        return 2;
    }
    if (bench_config(mode, n, &cfg) != 0) return 5;
    if (pyins_init(mem, sizeof mem, &cfg) != PYINS_OK) return 3;
    memset(&out, 0, sizeof out);
    for (i = 0; i < n; ++i) {
        bench_sample(mode, i, out.table_angle_cmd_rad, &s);
        if (pyins_step((pyins_core *)mem, &s, &out) != PYINS_OK) return 4;
    }
    printf("ticks %ld lat %.17g mode %d index_state %d\n", n, out.lat_rad, (int)out.mode, (int)out.index_state);
    return 0;
}
