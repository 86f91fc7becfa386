// c_api_testing.cpp: the test hooks of pyins_core_testing.h, host only.
//
// Each hook runs one core module alone on caller-provided arrays, so that
// the cross-check tests compare a module with its NumPy mirror without the
// firmware instance around it. Built only with PYINS_TEST_HOOKS (the host
// library; never the embedded images, where this unit is empty).
#if defined(PYINS_TEST_HOOKS) && PYINS_TEST_HOOKS
#include "pyins_core_testing.h"

#include "attitude.hpp"
#include "coarse_align.hpp"
#include "earth.hpp"
#include "fine_align.hpp"
#include "indexing.hpp"
#include "math_portable.hpp"
#include "moving_align.hpp"
#include "nav_filter.hpp"
#include "strapdown.hpp"

namespace {

using pyins::Mat3;

template <int N>
void fine_run(const pyins::fine_align::Params& prm, const double* dv, size_t n, double* x_out,
              double* p_out) {
    pyins::fine_align::FineAlign<N> f;
    pyins::fine_align::init<N>(f, prm);
    for (size_t k = 0; k < n; ++k) {
        pyins::fine_align::step<N>(f, pyins::Vec3(dv[3 * k], dv[3 * k + 1], dv[3 * k + 2]));
    }
    for (int i = 0; i < N; ++i) {
        x_out[i] = f.x(i);
        for (int j = 0; j < N; ++j) {
            p_out[N * i + j] = f.p(i, j);
        }
    }
}
using pyins::Quat;
using pyins::Vec3;

Vec3 v3(const double* a) { return Vec3(a[0], a[1], a[2]); }
void put3(const Vec3& v, double* a) { a[0] = v(0); a[1] = v(1); a[2] = v(2); }
Quat q4(const double* a) { return Quat{a[0], a[1], a[2], a[3]}; }
void put4(const Quat& q, double* a) { a[0] = q.w; a[1] = q.x; a[2] = q.y; a[3] = q.z; }
Mat3 m9(const double* a) {
    Mat3 m;
    m << a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8];
    return m;
}
void put9(const Mat3& m, double* a) {
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            a[3 * i + j] = m(i, j);
        }
    }
}

}  // namespace

extern "C" {

double pyins_t_sin(double x) { return pyins::pmath::sin(x); }
double pyins_t_cos(double x) { return pyins::pmath::cos(x); }
double pyins_t_atan2(double y, double x) { return pyins::pmath::atan2(y, x); }
void pyins_t_sin_batch(const double* x, double* out, size_t n) {
    for (size_t i = 0; i < n; ++i) out[i] = pyins::pmath::sin(x[i]);
}
void pyins_t_cos_batch(const double* x, double* out, size_t n) {
    for (size_t i = 0; i < n; ++i) out[i] = pyins::pmath::cos(x[i]);
}
void pyins_t_atan2_batch(const double* y, const double* x, double* out, size_t n) {
    for (size_t i = 0; i < n; ++i) out[i] = pyins::pmath::atan2(y[i], x[i]);
}

void pyins_t_principal_radii(double sin_lat, double* rm, double* rn) {
    const pyins::earth::PrincipalRadii r = pyins::earth::principal_radii(sin_lat);
    *rm = r.rm;
    *rn = r.rn;
}
double pyins_t_normal_gravity(double sin_lat, double height) {
    return pyins::earth::normal_gravity(sin_lat, height);
}
void pyins_t_earth_at(double sin_lat, double cos_lat, double height, const double vel_n[3],
                      pyins_t_earth* out) {
    const pyins::earth::Earth e = pyins::earth::earth_at(sin_lat, cos_lat, height, v3(vel_n));
    out->sin_lat = e.sin_lat;
    out->cos_lat = e.cos_lat;
    out->tan_lat = e.tan_lat;
    out->rm_h = e.rm_h;
    out->rn_h = e.rn_h;
    put3(e.omega_ie_n, out->omega_ie_n);
    put3(e.omega_en_n, out->omega_en_n);
    put3(e.omega_in_n, out->omega_in_n);
    put3(e.gravity_n, out->gravity_n);
}
void pyins_t_position_rate(double sin_lat, double cos_lat, double height, const double vel_n[3],
                           double out[3]) {
    const pyins::earth::Earth e = pyins::earth::earth_at(sin_lat, cos_lat, height, v3(vel_n));
    put3(pyins::earth::position_rate(e, v3(vel_n)), out);
}

void pyins_t_quat_mul(const double p[4], const double q[4], double out[4]) {
    put4(pyins::attitude::quat_mul(q4(p), q4(q)), out);
}
void pyins_t_quat_normalize(const double q[4], double out[4]) {
    put4(pyins::attitude::quat_normalize(q4(q)), out);
}
void pyins_t_quat_to_mat(const double q[4], double m[9]) {
    put9(pyins::attitude::quat_to_mat(q4(q)), m);
}
void pyins_t_mat_to_quat(const double m[9], double q[4]) {
    put4(pyins::attitude::mat_to_quat(m9(m)), q);
}
void pyins_t_rotvec_to_quat(const double v[3], double q[4]) {
    put4(pyins::attitude::rotvec_to_quat(v3(v)), q);
}
void pyins_t_quat_to_rotvec(const double q[4], double v[3]) {
    put3(pyins::attitude::quat_to_rotvec(q4(q)), v);
}
void pyins_t_rot_z(double angle, double m[9]) { put9(pyins::attitude::rot_z(angle), m); }
void pyins_t_euler_to_mat(const double euler[3], double m[9]) {
    put9(pyins::attitude::euler_to_mat(v3(euler)), m);
}
void pyins_t_mat_to_euler(const double m[9], double euler[3]) {
    put3(pyins::attitude::mat_to_euler(m9(m)), euler);
}
void pyins_t_mat_orthonormalize(const double m[9], double out[9]) {
    put9(pyins::attitude::mat_orthonormalize(m9(m)), out);
}
double pyins_t_yaw_to_heading(double yaw) { return pyins::attitude::yaw_to_heading(yaw); }
double pyins_t_heading_to_yaw(double heading) { return pyins::attitude::heading_to_yaw(heading); }

void pyins_t_compensate(const double dtheta[3], const double dv[3], const double dtheta1[3],
                        const double dv1[3], const double dtheta2[3], const double dv2[3],
                        int32_t count, double phi[3], double dv_p[3]) {
    const pyins::strapdown::History h =
        pyins::strapdown::history_of(v3(dtheta1), v3(dv1), v3(dtheta2), v3(dv2), count);
    const pyins::strapdown::Compensated c = pyins::strapdown::compensate(v3(dtheta), v3(dv), h);
    put3(c.phi, phi);
    put3(c.dv_p, dv_p);
}

void pyins_t_strapdown_update(pyins_t_strapdown* s, const double dtheta_p[3], const double dv_p[3],
                              double dt) {
    pyins::strapdown::Strapdown sd;
    sd.nav.lat = s->lat;
    sd.nav.lon = s->lon;
    sd.nav.height = s->height;
    sd.nav.vel_n = v3(s->vel_n);
    sd.nav.quat_np = q4(s->quat_np);
    sd.hist = pyins::strapdown::history_of(v3(s->dtheta1), v3(s->dv1), v3(s->dtheta2), v3(s->dv2),
                                           s->hist_count);
    sd.prev_dvel_n = v3(s->prev_dvel_n);
    sd.vertical = s->vertical == 1 ? pyins::strapdown::Vertical::kFree
                                   : pyins::strapdown::Vertical::kHold;
    sd.ref_height = s->ref_height;
    sd.ref_lon = s->lon;
    sd.lat0 = s->lat;  // a state handed in: anchored at its own latitude
    pyins::pmath::sincos(sd.lat0, &sd.sin_lat0, &sd.cos_lat0);
    sd.terms = pyins::earth::position_terms(s->lat, sd.sin_lat0, sd.cos_lat0, s->height);
    pyins::strapdown::update(sd, v3(dtheta_p), v3(dv_p), dt);
    s->lat = sd.nav.lat;
    s->lon = sd.nav.lon;
    s->height = sd.nav.height;
    put3(sd.nav.vel_n, s->vel_n);
    put4(sd.nav.quat_np, s->quat_np);
    put3(sd.hist.dtheta1, s->dtheta1);
    put3(sd.hist.dv1, s->dv1);
    put3(sd.hist.dtheta2, s->dtheta2);
    put3(sd.hist.dv2, s->dv2);
    s->hist_count = sd.hist.count;
    put3(sd.prev_dvel_n, s->prev_dvel_n);
}

int pyins_t_fine_align_run(int32_t states, const pyins_t_fine_params* p, const double* dv_sf_n,
                           size_t n, double* x_out, double* p_out) {
    pyins::fine_align::Params prm;
    prm.sin_lat = p->sin_lat;
    prm.cos_lat = p->cos_lat;
    prm.gravity = p->gravity;
    prm.dt = p->dt;
    prm.meas_every = p->meas_every;
    prm.gyro_arw = p->gyro_arw;
    prm.accel_vrw = p->accel_vrw;
    prm.sigma0_att[0] = p->sigma0_att[0];
    prm.sigma0_att[1] = p->sigma0_att[1];
    prm.sigma0_att[2] = p->sigma0_att[2];
    prm.sigma0_gyro = p->sigma0_gyro;
    prm.sigma0_accel = p->sigma0_accel;
    prm.nis_window = 0;   // the hook runs the filter alone, without the integrity test
    prm.nis_max = 0.0;
    if (states == 5) {
        fine_run<5>(prm, dv_sf_n, n, x_out, p_out);
    } else if (states == 8) {
        fine_run<8>(prm, dv_sf_n, n, x_out, p_out);
    } else {
        return -1;
    }
    return 0;
}

void pyins_t_coarse_pos_i(double t, double sin_lat, double cos_lat, double gravity, double out[3]) {
    put3(pyins::coarse_align::pos_i(t, sin_lat, cos_lat, gravity), out);
}

void pyins_t_coarse_fit_weights(double s, double* phi_a, double* phi_b) {
    pyins::coarse_align::fit_weights(s, phi_a, phi_b);
}

void pyins_t_coarse_solve_fit(const double* grid, int32_t n, double t_step, double sin_lat,
                              double cos_lat, double gravity, double m[9]) {
    pyins::Vec3 g[pyins::coarse_align::kHistLen];
    const int32_t k_max = n < pyins::coarse_align::kHistLen ? n : pyins::coarse_align::kHistLen;
    for (int32_t k = 0; k < k_max; ++k) {
        g[k] = v3(grid + 3 * k);
    }
    put9(pyins::coarse_align::solve_fit(g, k_max, t_step, sin_lat, cos_lat, gravity), m);
}

void pyins_t_coarse_solve_eq8(const double vi1[3], const double vi2[3], const double vb1[3],
                              const double vb2[3], double m[9]) {
    put9(pyins::coarse_align::solve_eq8(v3(vi1), v3(vi2), v3(vb1), v3(vb2)), m);
}

double pyins_t_coarse_rotation_sine(const double a[9], const double b[9]) {
    return pyins::coarse_align::rotation_sine(m9(a), m9(b));
}

void pyins_t_coarse_mat_n_e_at(double sin_lat, double cos_lat, double sin_dlon, double cos_dlon, double m[9]) {
    put9(pyins::coarse_align::mat_n_e_at(sin_lat, cos_lat, sin_dlon, cos_dlon), m);
}

void pyins_t_coarse_known_force_i(double t, double sin_lat, double cos_lat, double sin_dlon, double cos_dlon,
                                  double gravity, double ve, double vn, double out[3]) {
    put3(pyins::coarse_align::known_force_i(t, sin_lat, cos_lat, sin_dlon, cos_dlon, gravity, ve, vn), out);
}

void pyins_t_coarse_ref_vel_i(double t, double sin_lat, double cos_lat, double sin_dlon, double cos_dlon,
                              double ve, double vn, double vu, double out[3]) {
    put3(pyins::coarse_align::ref_vel_i(t, sin_lat, cos_lat, sin_dlon, cos_dlon, ve, vn, vu), out);
}

void pyins_t_coarse_solve_vel_grid(const double* grid, const double* grid_i, int32_t n, double m[9]) {
    pyins::Vec3 g[pyins::coarse_align::kHistLen];
    pyins::Vec3 gi[pyins::coarse_align::kHistLen];
    const int32_t k_max = n < pyins::coarse_align::kHistLen ? n : pyins::coarse_align::kHistLen;
    for (int32_t k = 0; k < k_max; ++k) {
        g[k] = v3(grid + 3 * k);
        gi[k] = v3(grid_i + 3 * k);
    }
    put9(pyins::coarse_align::solve_vel_grid(g, gi, k_max), m);
}

double pyins_t_coarse_heading_sigma(int32_t n, double t_step, double var, double gravity, double cos_lat) {
    return pyins::coarse_align::heading_sigma(n, t_step, var, gravity, cos_lat);
}

namespace {
pyins::moving_align::Params moving_params(const pyins_t_moving_params* p) {
    pyins::moving_align::Params prm;
    prm.sin_lat = p->sin_lat;
    prm.cos_lat = p->cos_lat;
    prm.rm_h = p->rm_h;
    prm.rn_h = p->rn_h;
    prm.dt = p->dt;
    prm.meas_every = p->meas_every;
    prm.gyro_arw = p->gyro_arw;
    prm.accel_vrw = p->accel_vrw;
    prm.pos_sigma = p->pos_sigma;
    prm.sigma0_att[0] = p->sigma0_att[0];
    prm.sigma0_att[1] = p->sigma0_att[1];
    prm.sigma0_att[2] = p->sigma0_att[2];
    prm.sigma0_vel = p->sigma0_vel;
    prm.sigma0_gyro = p->sigma0_gyro;
    prm.sigma0_accel = p->sigma0_accel;
    prm.nis_window = p->nis_window;
    prm.nis_max = p->nis_max;
    prm.site_accel = p->site_accel;
    return prm;
}
}  // namespace

void pyins_t_moving_sigma0_after_coarse(const pyins_t_moving_params* p, double coarse_s, double wander,
                                        double gravity, double sigma0_att_out[3]) {
    pyins::moving_align::Params prm = moving_params(p);
    pyins::moving_align::sigma0_after_coarse(prm, coarse_s, wander, gravity);
    sigma0_att_out[0] = prm.sigma0_att[0];
    sigma0_att_out[1] = prm.sigma0_att[1];
    sigma0_att_out[2] = prm.sigma0_att[2];
}

int pyins_t_moving_align_run(const pyins_t_moving_params* p, const double* dv_sf_n, const double* z,
                             size_t n, double* x_out, double* p_out, double* nis_mean) {
    const pyins::moving_align::Params prm = moving_params(p);
    pyins::moving_align::MovingAlign m;
    pyins::moving_align::init(m, prm);
    int updates = 0;
    for (size_t k = 0; k < n; ++k) {
        if (pyins::moving_align::step(m, v3(dv_sf_n + 3 * k), z + 2 * k)) {
            updates = updates + 1;
        }
    }
    for (int i = 0; i < pyins::moving_align::kStates; ++i) {
        x_out[i] = m.x(i);
        for (int j = 0; j < pyins::moving_align::kStates; ++j) {
            p_out[pyins::moving_align::kStates * i + j] = m.p(i, j);
        }
    }
    *nis_mean = m.nis_mean;
    return updates;
}

namespace {
pyins::nav_filter::Motion nav_motion6(const double* m) {
    pyins::nav_filter::Motion mo;
    mo.sin_lat = m[0];
    mo.cos_lat = m[1];
    mo.rm_h = m[2];
    mo.rn_h = m[3];
    mo.vel_e = m[4];
    mo.vel_n = m[5];
    return mo;
}
}  // namespace

void pyins_t_nav_system_matrix(const double motion[6], const double f_n[3], const double c_np[9],
                               const double w_p[3], double f_out[133]) {
    namespace nf = pyins::nav_filter;
    const auto f = nf::system_matrix(nav_motion6(motion), v3(f_n), m9(c_np), v3(w_p));
    for (int i = 0; i < nf::kDyn; ++i) {
        for (int j = 0; j < nf::kStates; ++j) {
            f_out[nf::kStates * i + j] = f(i, j);
        }
    }
}

int pyins_t_nav_filter_run(const pyins_t_nav_params* p, const double c_np0[9], const double* dv_sf_n,
                           const double* dtheta_p, const double* motion, const double* c_np, const int32_t* kind,
                           const double* z, const double* r, size_t n, double* nis, double* x_out,
                           double* p_out, double* bias_out) {
    namespace nf = pyins::nav_filter;
    nf::Params prm;
    prm.dt = p->dt;
    prm.every = p->every;
    prm.reject_limit = p->reject_limit;
    prm.gyro_arw = p->gyro_arw;
    prm.accel_vrw = p->accel_vrw;
    prm.gate = p->gate;
    for (int i = 0; i < 3; ++i) {
        prm.sigma0_att[i] = p->sigma0_att[i];
    }
    prm.sigma0_vel = p->sigma0_vel;
    prm.sigma0_pos = p->sigma0_pos;
    prm.sigma0_gyro = p->sigma0_gyro;
    prm.sigma0_accel = p->sigma0_accel;
    prm.gyro_bias_rw = p->gyro_bias_rw;
    prm.table_scale = p->table_scale;
    prm.table_mis = p->table_mis;
    prm.level_scale = p->level_scale;
    prm.level_mis = p->level_mis;
    nf::NavFilter f;
    nf::init(f, prm, m9(c_np0));
    int updates = 0;
    for (size_t k = 0; k < n; ++k) {
        const nf::Motion mo = nav_motion6(motion + 6 * k);
        const Mat3 c = m9(c_np + 9 * k);
        nf::gather(f, v3(dv_sf_n + 3 * k), v3(dtheta_p + 3 * k));
        if (f.ticks == f.prm.every) {
            nf::predict(f, mo, c);
        }
        nis[k] = 0.0;
        if (kind[k] != 0) {
            nf::predict(f, mo, c);
            const int row = kind[k] == 1 ? nf::kPos : nf::kVel;
            nis[k] = nf::nis_pair(f, row, z + 2 * k, r + 2 * k);
            if (nis[k] <= prm.gate) {
                nf::update_pair(f, row, z + 2 * k, r + 2 * k);
                nf::reset_feedback(f);
                f.c_start = c;
                updates = updates + 1;
            }
        }
    }
    for (int i = 0; i < nf::kStates; ++i) {
        x_out[i] = f.x(i);
        for (int j = 0; j < nf::kStates; ++j) {
            p_out[nf::kStates * i + j] = f.p(i, j);
        }
    }
    for (int i = 0; i < 3; ++i) {
        bias_out[i] = f.gyro_bias(i);
        bias_out[3 + i] = f.accel_bias(i);
        bias_out[6 + i] = f.table_err(i);
    }
    for (int i = 0; i < 4; ++i) {
        bias_out[9 + i] = f.level_err[i];
    }
    return updates;
}

void pyins_t_indexing_run(const pyins_t_index_params* p, double meas0, const double* meas,
                          const double* yaw_b, size_t n, pyins_t_index_out* out) {
    pyins::indexing::Params prm;
    prm.n_steps = p->n_steps;
    for (int i = 0; i < pyins::indexing::kMaxSteps; ++i) {
        prm.steps[i].stop_ticks = p->stop_ticks[i];
        prm.steps[i].kind = static_cast<pyins::indexing::Kind>(p->kind[i]);
        prm.steps[i].angle = p->angle[i];
    }
    prm.rate = p->rate;
    prm.accel = p->accel;
    prm.delta = p->delta;
    prm.max_flex = p->max_flex;
    prm.tolerance = p->tolerance;
    prm.jump = p->jump;
    prm.timeout_ticks = p->timeout_ticks;
    prm.sums = p->sums;
    prm.dt = p->dt;
    prm.isolate = p->isolate;
    pyins::indexing::Indexer ix;
    pyins::indexing::init(ix, prm, meas0);
    for (size_t k = 0; k < n; ++k) {
        const double m = meas != nullptr ? meas[k] : ix.cmd_angle;
        double sn = 0.0;
        double cs = 0.0;
        if (pyins::indexing::wants_heading(ix)) {
            pyins::pmath::sincos(yaw_b[k] + m, &sn, &cs);
        }
        pyins::indexing::update(ix, m, sn, cs);
        out[k].state = static_cast<int32_t>(ix.state);
        out[k].step = ix.step;
        out[k].fault = static_cast<int32_t>(ix.fault);
        out[k].fallbacks = ix.fallbacks;
        out[k].cmd_angle = ix.cmd_angle;
        out[k].cmd_rate = ix.cmd_rate;
        out[k].a_c = ix.a_c;
        out[k].a_s = ix.a_s;
        out[k].motor_starts = ix.motor_starts;
        out[k].reserved = 0;
        out[k].travel = ix.travel;
    }
}

int32_t pyins_t_index_preset(int32_t scheme, int32_t stop_ticks, pyins_t_index_params* out) {
    pyins::indexing::Step steps[pyins::indexing::kMaxSteps];
    const int32_t n = pyins::indexing::preset_steps(scheme, stop_ticks, steps);
    for (int32_t i = 0; i < n; ++i) {
        out->stop_ticks[i] = steps[i].stop_ticks;
        out->kind[i] = static_cast<int32_t>(steps[i].kind);
        out->angle[i] = steps[i].angle;
    }
    out->n_steps = n < 0 ? 0 : n;
    return n;
}

}  // extern "C"
#endif  // PYINS_TEST_HOOKS
