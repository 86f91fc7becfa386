/* demo_scenario.h: a fixed firmware scenario built from integer arithmetic
 * only, so the host, the Cortex-M targets and Python (tools/compare_embedded.py)
 * feed the core exactly the same doubles: a static ship at 34.246 N with
 * small deterministic "noise" from a 64-bit LCG (scaled by powers of two,
 * hence exact), 60 s coarse alignment, 60 s fine alignment (5 states), then
 * navigation with the traditional two-position scheme (20 s stops) on an
 * ideal table that reads back the previous command. */
#ifndef PYINS_DEMO_SCENARIO_H
#define PYINS_DEMO_SCENARIO_H

#include <stdint.h>

#include "pyins_core.h"

#define DEMO_TICKS 24000u
#define DEMO_PRINT_EVERY 500u

#ifdef __cplusplus
extern "C" {
#endif

void demo_config(pyins_config *cfg);
/* The sample of tick k (0-based); state is the LCG state (start at 1). */
void demo_sample(uint64_t *state, double encoder_rad, pyins_sample *s);

#ifdef __cplusplus
}
#endif

#endif
