/* demo_scenario.h: a fixed firmware scenario built from integer arithmetic
 * only, so the host, the Cortex-M targets and Python (tools/compare_embedded.py)
 * feed the core exactly the same doubles: a ship moored at 34.246 N with
 * small deterministic "noise" from a 64-bit LCG (scaled by powers of two,
 * hence exact) and a sawtooth heave of 2 mg, the IMU 2 m from the reference
 * point (lever arm, sensor offset), 60 s of moving-base coarse alignment
 * (FIT), 60 s of moving-base fine alignment (12 states), then
 * navigation with the traditional two-position scheme (20 s stops) on an
 * ideal table that reads back the previous command. The IMU counts its
 * samples (seq checking on), and a fixed schedule of sample-level faults
 * (demo_fault) runs every fault path of docs/core.md on every target. */
#ifndef PYINS_DEMO_SCENARIO_H
#define PYINS_DEMO_SCENARIO_H

#include <stdint.h>

#include "pyins_core.h"

#define DEMO_TICKS 24000u
#define DEMO_PRINT_EVERY 500u

/* What happens to sample k (demo_fault). */
enum demo_fault_kind {
    DEMO_NONE = 0,
    DEMO_DROP = 1,            /* lost on the way: never stepped (a seq gap) */
    DEMO_REPEAT = 2,          /* stepped twice (a duplicate) */
    DEMO_NAN = 3,             /* dv_p[0] is NaN (rejected) */
    DEMO_SATURATE = 4,        /* dtheta_p[0] = 1 rad, beyond 400 deg/s (rejected) */
    DEMO_ENCODER_GLITCH = 5   /* the encoder reads 0.25 rad off: one jump, indexing FAULT, reset */
};

#ifdef __cplusplus
extern "C" {
#endif

void demo_config(pyins_config *cfg);
/* The fault schedule: enum demo_fault_kind of sample k (0-based). */
int demo_fault(uint32_t k);
/* The sample of tick k (0-based), seq = k + 1, with demo_fault(k)'s content
 * fault applied; state is the LCG state (start at 1). */
void demo_sample(uint64_t *state, uint32_t k, double encoder_rad, pyins_sample *s);

#ifdef __cplusplus
}
#endif

#endif
