/* bench_modes.h: the per-mode benchmark scenarios, the same on every build so
 * instruction counts compare: tools/bench_step.c on the host (callgrind) and
 * csrc/embedded/bench_main.c on Cortex-M7/M4F (QEMU -icount), both read by
 * tools/size_report.py.
 *
 * Modes (every tick of the run in that mode):
 *   nav     NAVIGATE, no indexing (the table fixed)
 *   navix   NAVIGATE with the two-position scheme, 3 s stops, the table
 *           reading back the command (stops and 6 deg/s moves)
 *   coarse  COARSE_ALIGN (first solution at 20 s, then one every 1 s)
 *   fine5   FINE_ALIGN, 5-state filter (measurement update every 10 ticks)
 *   fine8   FINE_ALIGN, 8-state filter
 *   fit     COARSE_ALIGN by FIT (moving base), a 2 m lever arm
 *   fine12  FINE_ALIGN, the moving-base 12-state filter (1 Hz updates), lever arm
 *   navund  NAVIGATE, nav_mode UNDAMPED: the strapdown alone, no filter at sea
 *   navgnss NAVIGATE, INTEGRATED: GNSS position and velocity at 1 Hz (pushed
 *           ahead, applied inside the step of their tick), every one used
 *           (the gate opened: the scenario's IMU is not a ship at rest, and
 *           the count wants the updates)
 *   navlog  NAVIGATE, the EM speed log alone at 5 Hz: the current learnt
 *           from its first 60 readings (12 s), DAMPED after 10 s of course
 *   fitvel  COARSE_ALIGN under way (FIT_VEL): GNSS velocity at 1 Hz taken
 *           into the inertial side as it comes, a 2 m lever arm
 * The IMU swings gently, so every branch of a moving step runs. The
 * references (bench_refs) are pushed before the step, outside the count
 * (pyins_push_ref only queues them). */
#ifndef PYINS_BENCH_MODES_H
#define PYINS_BENCH_MODES_H

#include <string.h>

#include "pyins_core.h"

enum { BENCH_NAV, BENCH_NAVIX, BENCH_COARSE, BENCH_FINE5, BENCH_FINE8, BENCH_FIT, BENCH_FINE12,
       BENCH_NAVUND, BENCH_NAVGNSS, BENCH_NAVLOG, BENCH_FITVEL, BENCH_N_MODES };

static const char *const bench_mode_name[BENCH_N_MODES] = {"nav", "navix", "coarse", "fine5", "fine8",
                                                           "fit", "fine12", "navund", "navgnss", "navlog",
                                                           "fitvel"};

/* The mode called name, or -1. */
static int bench_mode_of(const char *name) {
    int m;
    for (m = 0; m < BENCH_N_MODES; ++m) {
        if (strcmp(name, bench_mode_name[m]) == 0) return m;
    }
    return -1;
}

/* The configuration of an n-tick run in mode m; 0, or -1 if the mode cannot
 * last n ticks. */
static int bench_config(int m, long n, pyins_config *cfg) {
    pyins_config_default(cfg);
    cfg->lat_rad = 0.6;
    cfg->euler_b_rad[0] = 0.02;
    cfg->euler_b_rad[1] = -0.03;
    cfg->euler_b_rad[2] = 1.0;
    switch (m) {
        case BENCH_NAV:
            return 0;
        case BENCH_NAVIX:
            cfg->index_scheme = PYINS_INDEX_TWO_POSITION;
            cfg->index_stop_ticks = 300;
            return 0;
        case BENCH_COARSE:
            cfg->coarse_ticks = 25500;   /* the longest the storage allows at 1 s outputs */
            return n > cfg->coarse_ticks ? -1 : 0;
        case BENCH_FINE5:
        case BENCH_FINE8:
            cfg->fine_ticks = (int32_t)n + 1;
            cfg->fine_states = m == BENCH_FINE8 ? 8 : 5;
            return 0;
        case BENCH_FIT:
            cfg->coarse_ticks = (int32_t)n + 1;   /* FIT has no length limit */
            cfg->coarse_method = PYINS_COARSE_FIT;
            cfg->lever_b_m[0] = 0.5;
            cfg->lever_b_m[1] = 1.5;
            cfg->lever_b_m[2] = 1.2;
            return 0;
        case BENCH_FINE12:
            cfg->fine_ticks = (int32_t)n + 1;
            cfg->fine_states = 12;
            cfg->lever_b_m[0] = 0.5;
            cfg->lever_b_m[1] = 1.5;
            cfg->lever_b_m[2] = 1.2;
            return 0;
        case BENCH_NAVUND:
            cfg->nav_mode = PYINS_NAV_UNDAMPED;
            return 0;
        case BENCH_NAVGNSS:
            cfg->nav_gate = 1e30;
            return 0;
        case BENCH_NAVLOG:
            return 0;
        case BENCH_FITVEL:
            cfg->coarse_ticks = (int32_t)n + 1;
            cfg->coarse_method = PYINS_COARSE_FIT_VEL;
            cfg->fine_ticks = 0;
            cfg->lever_b_m[0] = 0.5;
            cfg->lever_b_m[1] = 1.5;
            cfg->lever_b_m[2] = 1.2;
            return 0;
        default:
            return -1;
    }
}

/* The references to push before sample i (0-based) of mode m, valid at the
 * end of its tick i + 1: up to 2 into refs; returns how many. Their values
 * vary (a repeat bit for bit reads as a frozen receiver). */
static int bench_refs(int m, long i, pyins_ref *refs) {
    const long t = i + 1;
    const double wiggle = (double)(t % 700) * 1e-3;
    int n = 0;
    memset(refs, 0, 2 * sizeof *refs);
    if (m == BENCH_FITVEL && t % 100 == 0) {
        refs[n].kind = PYINS_REF_GNSS_VEL;
        refs[n].tick = t;
        refs[n].value[0] = wiggle;
        refs[n].sigma[0] = refs[n].sigma[1] = refs[n].sigma[2] = 0.05;
        ++n;
    } else if (m == BENCH_NAVGNSS && t % 100 == 0) {
        refs[n].kind = PYINS_REF_GNSS_POS;
        refs[n].tick = t;
        refs[n].value[0] = 0.6 + wiggle * 1e-7;
        refs[n].value[1] = 0.0;
        refs[n].sigma[0] = refs[n].sigma[1] = refs[n].sigma[2] = 3.0;
        ++n;
        refs[n].kind = PYINS_REF_GNSS_VEL;
        refs[n].tick = t;
        refs[n].value[0] = wiggle;
        refs[n].sigma[0] = refs[n].sigma[1] = refs[n].sigma[2] = 0.05;
        ++n;
    } else if (m == BENCH_NAVLOG && t % 20 == 0) {
        refs[n].kind = PYINS_REF_SPEED_LOG;
        refs[n].tick = t;
        refs[n].value[0] = wiggle;
        refs[n].sigma[0] = 0.05;
        ++n;
    }
    return n;
}

/* Sample i (0-based); table_cmd_rad: the last output's commanded table
 * angle (the ideal table of navix reads it back; 0 otherwise). */
static void bench_sample(int m, long i, double table_cmd_rad, pyins_sample *s) {
    memset(s, 0, sizeof *s);
    s->dtheta_p_rad[0] = 1e-4 * (double)((i % 200) - 100) / 100.0;
    s->dtheta_p_rad[1] = 5e-7 + 5e-5 * (double)((i % 300) - 150) / 150.0;
    s->dtheta_p_rad[2] = 3e-7;
    s->dv_p_mps[0] = 1e-3;
    s->dv_p_mps[1] = -2e-3;
    s->dv_p_mps[2] = 0.0978;
    s->table_angle_rad = 0.0;
    if (m == BENCH_NAVIX) {
        double a = table_cmd_rad;
        while (a >= 6.283185307179586) a -= 6.283185307179586;
        while (a < 0.0) a += 6.283185307179586;
        s->table_angle_rad = a;
    }
}

#endif
