/* demo_main.c: run the demo scenarios (A, then B on a fresh instance:
 * demo_scenario.h) through the firmware and print, every
 * DEMO_PRINT_EVERY samples, the output record's mode, index state, fault
 * bits, tick, sample-level counters, the navigation mode and reference
 * counters, and key doubles as hex, one "S" line per sample whose status is
 * not PYINS_OK and one "R" line per reference the core refused (the same program on the host and
 * under QEMU on Cortex-M7 and M4F; the lines must be identical). An indexing
 * FAULT (from the scheduled encoder glitch) is reset. Ends with "DONE" and
 * returns 0, or prints the failing status. */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "demo_scenario.h"
#include "pyins_core.h"

static unsigned char g_mem[20480] __attribute__((aligned(16)));

static void put_hex(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    /* newlib-nano printf has no %ll: two 32-bit halves */
    printf(" %08lx%08lx", (unsigned long)(u >> 32), (unsigned long)(u & 0xffffffffu));
}

/* Run one demo on a fresh instance: b = 0 demo A (demo_config, demo_fault,
 * demo_refs), b = 1 demo B (demo_config_b, no faults, demo_refs_b); its
 * lines carry the sample number, demo B's prefixed "b". 0 or the failing
 * exit code. */
static int run_demo(int b, uint32_t ticks) {
    pyins_config cfg;
    pyins_sample s;
    pyins_output out;
    uint64_t lcg = 1;
    uint64_t lcg_refs = 12345u;
    double enc = 0.0;
    double cmd = 0.0, cmd_prev = 0.0;   /* the unwrapped commanded angle, now and a tick ago */
    const char *tag = b ? "b" : "";
    uint32_t k;
    int st;
    if (b) {
        demo_config_b(&cfg);
    } else {
        demo_config(&cfg);
    }
    st = pyins_init(g_mem, sizeof g_mem, &cfg);
    if (st != PYINS_OK) {
        printf("FAIL init %d %s\n", st, pyins_status_str(st));
        return 3;
    }
    for (k = 0; k < ticks; ++k) {
        const int fault = b ? DEMO_NONE : demo_fault(k);
        /* a dropped sample is lost on the way: the core sees the seq gap on the next one */
        const int steps = fault == DEMO_DROP ? 0 : (fault == DEMO_REPEAT ? 2 : 1);
        int rep;
        {
            /* the IMU turns with the table; a reset's jump of the command (the
               glitched reading it restarts from) is not a motion */
            const double step = cmd - cmd_prev;
            demo_sample(&lcg, k, fault, enc, step > 0.1 || step < -0.1 ? 0.0 : step, &s);
        }
        {
            pyins_ref refs[DEMO_MAX_REFS];
            const int n_refs = b ? demo_refs_b(&lcg_refs, k, refs) : demo_refs(&lcg_refs, k, refs);
            int r;
            for (r = 0; r < n_refs; ++r) {
                st = pyins_push_ref((pyins_core *)g_mem, &refs[r]);
                if (st != PYINS_OK) {
                    printf("%sR %lu %ld %d\n", tag, (unsigned long)k, (long)refs[r].kind, st);
                }
            }
        }
        for (rep = 0; rep < steps; ++rep) {
            st = pyins_step((pyins_core *)g_mem, &s, &out);
            if (st != PYINS_OK) {
                printf("%sS %lu %d\n", tag, (unsigned long)k, st);
            }
            /* only the scheduled rejections are expected */
            if (st < 0 && !(fault == DEMO_NAN && st == PYINS_E_SAMPLE_NONFINITE) &&
                !(fault == DEMO_SATURATE && st == PYINS_E_SAMPLE_SATURATED)) {
                printf("FAIL step %s%lu %d %s\n", tag, (unsigned long)k, st, pyins_status_str(st));
                return 4;
            }
        }
        if (out.index_state == PYINS_INDEX_FAULT) {
            pyins_index_reset((pyins_core *)g_mem);
            pyins_get_output((pyins_core *)g_mem, &out);   /* the command after the reset */
        }
        /* ideal table: the encoder reads the commanded angle, wrapped */
        cmd_prev = cmd;
        cmd = out.table_angle_cmd_rad;
        enc = cmd;
        while (enc >= 6.283185307179586) enc -= 6.283185307179586;
        while (enc < 0.0) enc += 6.283185307179586;
        if ((k + 1u) % DEMO_PRINT_EVERY == 0u) {
            printf("%s%lu %ld %ld %lx %ld %lu/%lu/%lu/%lu/%lu/%lu/%lu", tag, (unsigned long)(k + 1u), (long)out.mode,
                   (long)out.index_state, (unsigned long)out.fault_flags, (long)out.tick,
                   (unsigned long)out.n_nonfinite, (unsigned long)out.n_saturated,
                   (unsigned long)out.n_seq_gaps, (unsigned long)out.n_seq_bridged,
                   (unsigned long)out.n_seq_repeats, (unsigned long)out.n_seq_lost,
                   (unsigned long)out.n_encoder_jumps);
            /* at sea: mode in effect, references in use, used/rejected GNSS pos, vel, log and DVL */
            printf(" %ld/%lx/%lu/%lu/%lu/%lu/%lu/%lu/%lu/%lu", (long)out.nav_mode, (unsigned long)out.ref_in_use,
                   (unsigned long)out.n_ref_used[0], (unsigned long)out.n_ref_rejected[0],
                   (unsigned long)out.n_ref_used[1], (unsigned long)out.n_ref_rejected[1],
                   (unsigned long)out.n_ref_used[2], (unsigned long)out.n_ref_rejected[2],
                   (unsigned long)out.n_ref_used[3], (unsigned long)out.n_ref_rejected[3]);
            put_hex(out.lat_rad);
            put_hex(out.lon_rad);
            put_hex(out.vel_n_mps[0]);
            put_hex(out.vel_n_mps[1]);
            put_hex(out.quat_nb[0]);
            put_hex(out.quat_nb[1]);
            put_hex(out.quat_nb[2]);
            put_hex(out.quat_nb[3]);
            put_hex(out.kf_x[2]);
            put_hex(out.table_angle_cmd_rad);
            put_hex(out.index_a_c);
            put_hex(out.nav_sigma_pos_m);
            put_hex(out.nav_gyro_bias_rad_s[0]);
            put_hex(out.nav_nis[0]);
            printf("\n");
        }
    }
    return 0;
}

int main(void) {
    int rc;
    if (pyins_core_size() > sizeof g_mem) {
        printf("FAIL instance %lu bytes > %lu\n", (unsigned long)pyins_core_size(), (unsigned long)sizeof g_mem);
        return 2;
    }
    printf("pyins demo, ABI %lx, instance %lu bytes\n", (unsigned long)pyins_abi_version(),
           (unsigned long)pyins_core_size());
    rc = run_demo(0, DEMO_TICKS);
    if (rc != 0) {
        return rc;
    }
    printf("demo B: alignment under way (FIT_VEL) and in navigation\n");
    rc = run_demo(1, DEMO_B_TICKS);
    if (rc != 0) {
        return rc;
    }
    printf("DONE\n");
    return 0;
}
