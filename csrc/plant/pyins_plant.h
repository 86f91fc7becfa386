/*
 * pyins_plant.h: the simulated plant for firmware-in-the-loop runs (host
 * only, not part of the firmware): a turntable following the firmware's
 * motor command, the exact increments of the turning IMU, the sensor errors,
 * and the closed loop firmware -> motor -> table -> IMU -> firmware, stepped
 * in compiled code. Mirrored in NumPy by pyins/sim/turntable.py.
 *
 * The ship's body rate and specific force at the Gauss-Legendre nodes of each
 * tick come precomputed from pyins.sim (open loop: the ship does not feel
 * the table); the turntable angle inside the tick is analytic (constant
 * acceleration per tick), so the increments stay exact integrals.
 */
#ifndef PYINS_PLANT_H
#define PYINS_PLANT_H

#include <stddef.h>
#include <stdint.h>

#include "pyins_core.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#pragma GCC visibility push(default)
#endif

/* CDEF-BEGIN */

/* Turntable faults, for the fault tests. */
enum pyins_table_fault {
    PYINS_TABLE_OK = 0,
    PYINS_TABLE_STALL = 1,        /* from fault_tick the table brakes to a stop and stays */
    PYINS_TABLE_REVERSE = 2,      /* from fault_tick it turns against the command */
    PYINS_TABLE_JUMP = 3          /* from fault_tick the encoder reads jump_rad too much */
};

typedef struct pyins_table_config {
    double rate_max_rad_s;        /* motor rate limit [rad/s] */
    double accel_max_rad_s2;      /* motor acceleration limit [rad/s^2] */
    double encoder_lsb_rad;       /* encoder quantisation step [rad]; 0 = none */
    double jump_rad;              /* encoder jump of the JUMP fault [rad] */
    int64_t fault_tick;           /* tick from which the fault acts */
    int32_t fault;                /* enum pyins_table_fault */
    int32_t reserved;
} pyins_table_config;

/* Sensor errors in the IMU frame p (pyins.sim.sensors model):
 * measured = M true + bias dt + noise, then quantised with carried residual. */
typedef struct pyins_imu_errors {
    double gyro_m[9];             /* I + diag(scale) + misalignment, row-major */
    double gyro_bias_rad_s[3];
    double gyro_quantum_rad;      /* 0 = none */
    double accel_m[9];
    double accel_bias_mps2[3];
    double accel_quantum_mps;     /* 0 = none */
} pyins_imu_errors;

/* Plant state carried from one call to the next. */
typedef struct pyins_plant_state {
    int64_t tick;                 /* ticks done */
    double alpha_rad;             /* true table angle (unwrapped) */
    double rate_rad_s;            /* true table rate */
    double rate_cmd_rad_s;        /* the firmware's last motor command */
    double gyro_residual[3];      /* quantiser residuals */
    double accel_residual[3];
} pyins_plant_state;

/* One kept record of the plant, beside the firmware's output record. */
typedef struct pyins_plant_record {
    int64_t tick;
    double alpha_rad;
    double rate_rad_s;
    double encoder_rad;
} pyins_plant_record;

/* Run n ticks of the closed loop. For tick k (0-based in this call), the
 * ship's omega_ib^b and f^b at node j are node_omega_b / node_force_b
 * [((phase0 + k) % period) * n_nodes + j][3]; node_x, node_w are the
 * Gauss-Legendre abscissae on [-1, 1] and weights. node_sum_omega /
 * node_sum_force (may be NULL) are, per tick of the period [(phase0 + k) %
 * period][3], the weighted node sums sum_j node_w[j] * value[j] summed from
 * 0.0 in the order j = 0 .. n_nodes - 1: what a tick with the table at rest
 * takes (NULL: summed at every such tick; the same bits either way).
 * gyro_noise / accel_noise
 * (n x 3, may be NULL) are added per tick [rad, m/s]. After every tick whose
 * number (st->tick after it) is a multiple of every, the firmware's output
 * and the plant record are written (capacity must hold n / every + 1).
 * Each sample's seq is the tick number it ends (st->tick after it, modulo
 * 2^32). Stops at the first tick the firmware rejects (a PYINS_W_* notice
 * does not stop it); *n_done ticks were run.
 * Returns PYINS_OK or the firmware's / a negative pyins_status. */
int pyins_fil_run(pyins_core *core, pyins_plant_state *st, const pyins_table_config *table,
                  const pyins_imu_errors *err, const double *node_omega_b, const double *node_force_b,
                  const double *node_x, const double *node_w, const double *node_sum_omega,
                  const double *node_sum_force, int32_t n_nodes, int64_t period,
                  int64_t phase0, const double *gyro_noise, const double *accel_noise, size_t n,
                  double dt, size_t every, pyins_output *outputs, pyins_plant_record *records,
                  size_t capacity, size_t *n_done, size_t *n_out);

/* CDEF-END */

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#ifdef __cplusplus
}
#endif

#endif /* PYINS_PLANT_H */
