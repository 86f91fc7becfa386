/* bench_step.c: drive the firmware for instruction counting.
 *   valgrind --tool=callgrind --toggle-collect=pyins_step ./bench_step 10000 [MODE [API]]
 * counts the instructions inside one API function only (repeatable, unlike
 * time). MODE: nav (default), navix, coarse, fine5, fine8, fit, fine12, navund,
 * navgnss, navlog, fitvel: every
 * step in that mode (csrc/embedded/bench_modes.h: the same scenarios as the
 * Cortex-M bench image). API, how the caller takes the records (toggle
 * callgrind on the function named):
 *   step      pyins_step, a full record every tick (default)
 *   run       pyins_run, blocks of 100 samples, a full record every tick
 *   null      pyins_run, blocks of 100 samples, no records (outputs NULL)
 *   every100  pyins_run_decimated, blocks of 100 samples, one record per block
 *   compact   pyins_run_nav, blocks of 100 samples, a compact record (pyins_nav) every tick
 * In the block modes the encoder reads back the command of the block's last
 * record (pyins_get_output between blocks, outside the counted function).
 * tools/bench_strapdown.py, tools/bench_alignment.py and tools/size_report.py
 * run this. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_modes.h"
#include "pyins_core.h"

enum { API_STEP, API_RUN, API_NULL, API_EVERY100, API_COMPACT };
#define BLOCK 100

int main(int argc, char **argv) {
    const long n = argc > 1 ? atol(argv[1]) : 10000;
    const char *name = argc > 2 ? argv[2] : "nav";
    const char *api_name = argc > 3 ? argv[3] : "step";
    const int mode = bench_mode_of(name);
    static unsigned char mem[20 * 1024] __attribute__((aligned(64)));
    static pyins_sample block[BLOCK];
    static pyins_output records[BLOCK + 1];
    static pyins_nav navs[BLOCK + 1];
    pyins_config cfg;
    pyins_sample s;
    pyins_output out;
    int api;
    long i;
    if (strcmp(api_name, "step") == 0) api = API_STEP;
    else if (strcmp(api_name, "run") == 0) api = API_RUN;
    else if (strcmp(api_name, "null") == 0) api = API_NULL;
    else if (strcmp(api_name, "every100") == 0) api = API_EVERY100;
    else if (strcmp(api_name, "compact") == 0) api = API_COMPACT;
    else {
        fprintf(stderr, "unknown API %s (step, run, null, every100, compact)\n", api_name);
        return 2;
    }
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
    if (api == API_STEP) {
        for (i = 0; i < n; ++i) {
            pyins_ref refs[2];
            const int n_refs = bench_refs(mode, i, refs);
            int r;
            for (r = 0; r < n_refs; ++r) {
                if (pyins_push_ref((pyins_core *)mem, &refs[r]) != PYINS_OK) return 6;
            }
            bench_sample(mode, i, out.table_angle_cmd_rad, &s);
            if (pyins_step((pyins_core *)mem, &s, &out) != PYINS_OK) return 4;
        }
    } else {
        for (i = 0; i < n; i += BLOCK) {
            const long m = n - i < BLOCK ? n - i : BLOCK;
            size_t done = 0, n_out = 0;
            long k;
            int st;
            for (k = 0; k < m; ++k) {
                pyins_ref refs[2];
                const int n_refs = bench_refs(mode, i + k, refs);
                int r;
                for (r = 0; r < n_refs; ++r) {   /* at most 5 a block: the queue holds 8 */
                    if (pyins_push_ref((pyins_core *)mem, &refs[r]) != PYINS_OK) return 6;
                }
                bench_sample(mode, i + k, out.table_angle_cmd_rad, &block[k]);
            }
            if (api == API_COMPACT) {
                st = pyins_run_nav((pyins_core *)mem, block, (size_t)m, 1, navs, BLOCK + 1, &done, &n_out);
            } else if (api == API_EVERY100) {
                st = pyins_run_decimated((pyins_core *)mem, block, (size_t)m, BLOCK, records, BLOCK + 1,
                                         &done, &n_out);
            } else {
                st = pyins_run((pyins_core *)mem, block, (size_t)m, api == API_RUN ? records : NULL, &done);
            }
            if (st != PYINS_OK) return 4;
            pyins_get_output((const pyins_core *)mem, &out);
        }
    }
    printf("ticks %ld lat %.17g mode %d index_state %d nav_mode %d used %u/%u/%u\n", n, out.lat_rad, (int)out.mode,
           (int)out.index_state, (int)out.nav_mode, out.n_ref_used[0], out.n_ref_used[1], out.n_ref_used[2]);
    return 0;
}
