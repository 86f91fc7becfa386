/*
 * pyins_core_testing.h: UNSTABLE, host-only test hooks of the pyins core.
 *
 * Pure functions of the core's modules, exported so tests can hold each one
 * against the NumPy reference (pyins/reference) on random inputs. Built only
 * with PYINS_TEST_HOOKS (the host library); never part of the stable ABI.
 * Matrices are 3x3 row-major double[9]; quaternions [w, x, y, z].
 */
#ifndef PYINS_CORE_TESTING_H
#define PYINS_CORE_TESTING_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#pragma GCC visibility push(default)
#endif

/* CDEF-BEGIN */

typedef struct pyins_t_earth {
    double sin_lat, cos_lat, tan_lat, rm_h, rn_h;
    double omega_ie_n[3], omega_en_n[3], omega_in_n[3], gravity_n[3];
} pyins_t_earth;

typedef struct pyins_t_strapdown {
    double lat, lon, height;
    double vel_n[3];
    double quat_np[4];
    double dtheta1[3], dv1[3], dtheta2[3], dv2[3], prev_dvel_n[3];
    int32_t hist_count;
    int32_t vertical;
    double ref_height;
} pyins_t_strapdown;

typedef struct pyins_t_fine_params {
    double sin_lat, cos_lat, gravity, dt;
    int32_t meas_every;
    int32_t reserved;
    double gyro_arw, accel_vrw;
    double sigma0_att[3];
    double sigma0_gyro, sigma0_accel;
} pyins_t_fine_params;

typedef struct pyins_t_index_params {
    int32_t stop_ticks[8];
    int32_t kind[8];
    double angle[8];
    int32_t n_steps;
    int32_t timeout_ticks;
    int32_t sums;                 /* enum pyins_index_sums */
    int32_t isolate;              /* 1: heading isolation */
    double rate, accel, delta, max_flex, tolerance, jump, dt;
} pyins_t_index_params;

typedef struct pyins_t_index_out {
    int32_t state, step, fault, fallbacks;
    double cmd_angle, cmd_rate, a_c, a_s;
    int32_t motor_starts, reserved;
    double travel;
} pyins_t_index_out;

typedef struct pyins_t_moving_params {
    double sin_lat, cos_lat, rm_h, rn_h, dt;
    int32_t meas_every;
    int32_t nis_window;
    double gyro_arw, accel_vrw, pos_sigma;
    double sigma0_att[3];
    double sigma0_vel, sigma0_gyro, sigma0_accel, nis_max;
    double site_accel;
} pyins_t_moving_params;

/* coarse_align (moving base) */
void pyins_t_coarse_pos_i(double t, double sin_lat, double cos_lat, double gravity, double out[3]);
void pyins_t_coarse_fit_weights(double s, double *phi_a, double *phi_b);
void pyins_t_coarse_solve_fit(const double *grid, int32_t n, double t_step, double sin_lat,
                              double cos_lat, double gravity, double m[9]);
double pyins_t_coarse_rotation_sine(const double a[9], const double b[9]);
/* coarse_align: seed 000 eq. 8 as printed (row-major C_ib0^i) */
void pyins_t_coarse_solve_eq8(const double vi1[3], const double vi2[3], const double vb1[3],
                              const double vb2[3], double m[9]);
/* coarse_align under way (FIT_VEL): C_e^n at the reference point (row-major), g up^i + C_n^i (w_ie^n x v)
 * and C_n^i v at time t, the solution from v^ib0 (grid, n x 3) and the i side (grid_i, n x 3; n at
 * most 256), the heading sigma */
void pyins_t_coarse_mat_n_e_at(double sin_lat, double cos_lat, double sin_dlon, double cos_dlon, double m[9]);
void pyins_t_coarse_known_force_i(double t, double sin_lat, double cos_lat, double sin_dlon, double cos_dlon,
                                  double gravity, double ve, double vn, double out[3]);
void pyins_t_coarse_ref_vel_i(double t, double sin_lat, double cos_lat, double sin_dlon, double cos_dlon,
                              double ve, double vn, double vu, double out[3]);
void pyins_t_coarse_solve_vel_grid(const double *grid, const double *grid_i, int32_t n, double m[9]);
double pyins_t_coarse_heading_sigma(int32_t n, double t_step, double var, double gravity, double cos_lat);

/* moving_align: n ticks of dv_sf_n (n x 3) and z (n x 2, read at the update
 * ticks); writes x (12) and P (144, row-major); returns the number of
 * updates, and the last window mean NIS in *nis_mean. */
int pyins_t_moving_align_run(const pyins_t_moving_params *p, const double *dv_sf_n, const double *z,
                             size_t n, double *x_out, double *p_out, double *nis_mean);
/* moving_align::sigma0_after_coarse on p's sigma0_att: writes the result */
void pyins_t_moving_sigma0_after_coarse(const pyins_t_moving_params *p, double coarse_s, double wander,
                                        double gravity, double sigma0_att_out[3]);

/* nav_filter: the settings as nav_filter::Params' fields */
typedef struct pyins_t_nav_params {
    double dt;
    int32_t every;
    int32_t reject_limit;
    double gyro_arw, accel_vrw, gate;
    double sigma0_att[3];
    double sigma0_vel, sigma0_pos, sigma0_gyro, sigma0_accel;
    double gyro_bias_rw, table_scale, table_mis, level_scale, level_mis;
} pyins_t_nav_params;

/* nav_filter::system_matrix: motion = [sin_lat, cos_lat, rm_h, rn_h, vel_e, vel_n],
 * c_np row-major, w_p the mean rate in p; writes F's 7 dynamic rows (7 x 19, row-major) */
void pyins_t_nav_system_matrix(const double motion[6], const double f_n[3], const double c_np[9],
                               const double w_p[3], double f_out[133]);
/* nav_filter over n ticks from c_np0: each tick gathers dv_sf_n (n x 3) with
 * the angle increment dtheta_p (n x 3) and predicts when `every` ticks are in, at motion (n x 6) and c_np (n x 9);
 * a tick with kind[k] (1: position rows, 2: velocity rows; 0: none)
 * predicts up to it, takes the NIS of z, r (n x 2 each) into nis[k] and,
 * within the gate, updates and resets the feedback. Writes x (19), P (361),
 * the compensations: gyro biases, accelerometer biases, table-axis errors,
 * level gyro errors (3 + 3 + 3 + 4); returns the number of updates. */
int pyins_t_nav_filter_run(const pyins_t_nav_params *p, const double c_np0[9], const double *dv_sf_n,
                           const double *dtheta_p, const double *motion, const double *c_np, const int32_t *kind,
                           const double *z, const double *r, size_t n, double *nis, double *x_out,
                           double *p_out, double *bias_out);

/* math_portable */
double pyins_t_sin(double x);
double pyins_t_cos(double x);
double pyins_t_atan2(double y, double x);
void pyins_t_sin_batch(const double *x, double *out, size_t n);
void pyins_t_cos_batch(const double *x, double *out, size_t n);
void pyins_t_atan2_batch(const double *y, const double *x, double *out, size_t n);

/* earth */
void pyins_t_principal_radii(double sin_lat, double *rm, double *rn);
double pyins_t_normal_gravity(double sin_lat, double height);
void pyins_t_earth_at(double sin_lat, double cos_lat, double height,
                      const double vel_n[3], pyins_t_earth *out);
void pyins_t_position_rate(double sin_lat, double cos_lat, double height,
                           const double vel_n[3], double out[3]);

/* attitude */
void pyins_t_quat_mul(const double p[4], const double q[4], double out[4]);
void pyins_t_quat_normalize(const double q[4], double out[4]);
void pyins_t_quat_to_mat(const double q[4], double m[9]);
void pyins_t_mat_to_quat(const double m[9], double q[4]);
void pyins_t_rotvec_to_quat(const double v[3], double q[4]);
void pyins_t_quat_to_rotvec(const double q[4], double v[3]);
void pyins_t_rot_z(double angle, double m[9]);
void pyins_t_euler_to_mat(const double euler[3], double m[9]);
void pyins_t_mat_to_euler(const double m[9], double euler[3]);
void pyins_t_mat_orthonormalize(const double m[9], double out[9]);
double pyins_t_yaw_to_heading(double yaw);
double pyins_t_heading_to_yaw(double heading);

/* strapdown */
void pyins_t_compensate(const double dtheta[3], const double dv[3],
                        const double dtheta1[3], const double dv1[3],
                        const double dtheta2[3], const double dv2[3], int32_t count,
                        double phi[3], double dv_p[3]);
void pyins_t_strapdown_update(pyins_t_strapdown *s, const double dtheta_p[3],
                              const double dv_p[3], double dt);

/* fine_align: init, then n steps on the specific-force increments
 * dv_sf_n[3 n]; writes x (states values) and P (states x states, row-major).
 * Returns 0, or -1 if states is not 5 or 8. */
int pyins_t_fine_align_run(int32_t states, const pyins_t_fine_params *prm, const double *dv_sf_n,
                           size_t n, double *x_out, double *p_out);

/* indexing: init at meas0, then n ticks. meas[k] is the unwrapped encoder
 * angle of tick k, or with meas == NULL an ideal table that is where it was
 * commanded one tick before. The IMU yaw given to the machine is
 * yaw_b[k] + meas (ship yaw plus table angle). */
void pyins_t_indexing_run(const pyins_t_index_params *prm, double meas0, const double *meas,
                          const double *yaw_b, size_t n, pyins_t_index_out *out);
/* The steps of a preset scheme (enum pyins_index_scheme) with the given stop
 * length; returns the number of steps (0..8), or -1 for an unknown scheme. */
int32_t pyins_t_index_preset(int32_t scheme, int32_t stop_ticks, pyins_t_index_params *out);

/* CDEF-END */

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#ifdef __cplusplus
}
#endif

#endif /* PYINS_CORE_TESTING_H */
