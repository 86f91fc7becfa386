/* demo_scenario.h: a fixed firmware scenario built from integer arithmetic
 * only, so the host, the Cortex-M targets and Python (tools/compare_embedded.py)
 * feed the core exactly the same doubles: a ship moored at 34.246 N with
 * small deterministic "noise" from a 64-bit LCG (scaled by powers of two,
 * hence exact) and a sawtooth heave of 2 mg, the IMU 2 m from the reference
 * point (lever arm, sensor offset), 60 s of moving-base coarse alignment
 * (FIT), 60 s of moving-base fine alignment (12 states), then
 * navigation with the traditional two-position scheme (20 s stops) on an
 * ideal table that reads back the previous command, the IMU turning with
 * it (the Earth rate's sign at the 180 deg stop exact, approximate only in
 * a move). The IMU counts its
 * samples (seq checking on), and a fixed schedule of sample-level faults
 * (demo_fault) runs every fault path of docs/core.md on every target.
 * In navigation the ship gets external references (demo_refs): GNSS
 * position (0.2 s late) and velocity at 1 Hz, with one 600 m outlier the
 * gate rejects (INTEGRATED), then the EM speed log alone (DAMPED after its
 * 10 s of straight course), a DVL in bottom track for 15 s with a mounting
 * rotation and a lever arm (INTEGRATED), the log alone again, so the
 * integrated filter, the gate, the latency compensation, the damping and
 * the DVL's measurement run on every target too. */
#ifndef PYINS_DEMO_SCENARIO_H
#define PYINS_DEMO_SCENARIO_H

#include <stdint.h>

#include "pyins_core.h"

#define DEMO_TICKS 24000u
#define DEMO_PRINT_EVERY 500u
/* Demo B (after demo A, on a fresh instance): the alignment under way
 * (PYINS_COARSE_FIT_VEL, 60 s, GNSS velocity from the first second) and the
 * alignment in navigation that follows it (no fine phase: the navigation
 * filter starts on the coarse attitude, GNSS-aided, the table indexed), on
 * the same moored ship (0 kn: the velocity references are the receiver's
 * noise about zero, the heave in the vertical); no sample faults. */
#define DEMO_B_TICKS 12000u

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
/* Demo B's configuration: demo A's with the coarse method FIT_VEL, no fine
 * phase. */
void demo_config_b(pyins_config *cfg);
/* The fault schedule: enum demo_fault_kind of sample k (0-based). */
int demo_fault(uint32_t k);
/* The sample of tick k (0-based), seq = k + 1, with the content fault
 * `fault` (enum demo_fault_kind: demo_fault(k) in demo A, DEMO_NONE in B)
 * applied; state is the LCG state (start at 1); table_step_rad the table's
 * turn over the tick (the IMU turns with it). */
void demo_sample(uint64_t *state, uint32_t k, int fault, double encoder_rad, double table_step_rad,
                 pyins_sample *s);

/* The references to push before stepping sample k (0-based): writes up to
 * DEMO_MAX_REFS into refs and returns how many; state is their noise's LCG
 * (start at 12345, apart from the samples'). */
#define DEMO_MAX_REFS 2
int demo_refs(uint64_t *state, uint32_t k, pyins_ref *refs);
/* Demo B's references before sample k: GNSS velocity (3-axis sigma: the
 * vertical used) every second from the first, and the fix of each second
 * pushed 0.2 s late (as demo A's), from the first second on. */
int demo_refs_b(uint64_t *state, uint32_t k, pyins_ref *refs);

#ifdef __cplusplus
}
#endif

#endif
