// firmware.cpp: see firmware.hpp. Mirrored by pyins/reference/firmware.py.
#include "firmware.hpp"

#include <cmath>

#include "angle.hpp"
#include "attitude.hpp"
#include "config.hpp"
#include "earth.hpp"
#include "math_portable.hpp"

namespace pyins::firmware {

using angle::wrap_pi;
using angle::wrap_two_pi;

namespace {

/// Every component finite and inside the limit (a NaN compares false).
bool within(const double v[3], double limit) {
    return std::fabs(v[0]) < limit && std::fabs(v[1]) < limit && std::fabs(v[2]) < limit;
}

}  // namespace

void Firmware::init(const pyins_config& raw) {
    const pyins_config cfg = config::config_resolved(raw);
    cfg_ = cfg;
    // After a coarse alignment the static filter's attitude sigmas left 0
    // stay 0 here: start_fine fits them to the coarse result
    // (fine_align::sigma0_after_coarse). The moving-base filter keeps its
    // default, already FIT's result with margin (config.hpp).
    if (cfg.coarse_ticks > 0 && fine_filter::static_base(cfg.fine_states)) {
        for (int i = 0; i < 3; ++i) {
            if (raw.fine_sigma0_att_rad[i] == 0.0) {
                cfg_.fine_sigma0_att_rad[i] = 0.0;
            }
        }
    }
    dt_ = 1.0 / static_cast<double>(cfg.tick_hz);
    mode_ = Mode::kIdle;
    att_valid_ = cfg.coarse_ticks == 0;
    fine_.clear();
    fine_tick_ = 0;
    align_restarts_ = 0;
    gap_pending_ = false;
    faults_ = 0u;
    tick_ = 0;
    table_angle_ = cfg.table_angle_rad;
    encoder_ = wrap_two_pi(cfg.table_angle_rad);
    pmath::sincos(0.5 * encoder_, &enc_sin_half_, &enc_cos_half_);
    seq_ = 0u;
    seq_valid_ = false;
    last_dtheta_ = Vec3::Zero();
    last_dv_ = Vec3::Zero();
    counts_ = SampleCounts{0u, 0u, 0u, 0u, 0u, 0u, 0u};
    has_lever_ = 0;
    for (int i = 0; i < 3; ++i) {
        if (cfg.lever_b_m[i] != 0.0 || cfg.lever_p_m[i] != 0.0) {
            has_lever_ = 1;
        }
    }
    rate_count_ = 0;
    rate_p_ = Vec3::Zero();
    alpha_rate_ = 0.0;
    prev_dtheta_ = Vec3::Zero();
    prev_dalpha_ = 0.0;
    lever_vel_n_ = Vec3::Zero();
    lever_refine_ = 0;
    integrity_lost_ = 0;
    nav_on_ = 0;
    refq_head_ = 0;
    refq_count_ = 0;
    // the rates the lever arms need: the IMU's (has_lever_), the DVL's or the antenna's
    const double* dl = cfg.dvl_lever_b_m;
    const double* gl = cfg.gnss_lever_b_m;
    rates_on_ = has_lever_ != 0 || dl[0] != 0.0 || dl[1] != 0.0 || dl[2] != 0.0 || gl[0] != 0.0 || gl[1] != 0.0 ||
                        gl[2] != 0.0
                    ? 1
                    : 0;
    ref_last_tick_ = -1;
    for (int32_t i = 0; i < kRefKinds; ++i) {
        n_ref_used_[i] = 0u;
        n_ref_rejected_[i] = 0u;
        n_ref_skipped_[i] = 0u;
        ref_reject_run_[i] = 0;
        ref_out_[i] = 0;
        ref_used_tick_[i] = -1;
        nav_nis_[i] = 0.0;
        n_ref_stale_[i] = 0u;
        ref_seen_[i] = 0;
        ref_seen_tick_[i] = -1;
        ref_seen_value_[i][0] = 0.0;
        ref_seen_value_[i][1] = 0.0;
        ref_seen_vel_[i][0] = 0.0;
        ref_seen_vel_[i][1] = 0.0;
        damp_ref_[i][0] = 0.0;
        damp_ref_[i][1] = 0.0;
    }
    reserved_ref_ = 0;
    log_speed_ = 0.0;
    current_n_[0] = 0.0;
    current_n_[1] = 0.0;
    bow_last_[0] = 0.0;
    bow_last_[1] = 0.0;
    turn_rate_f_ = 0.0;
    damp_int_[0] = 0.0;
    damp_int_[1] = 0.0;
    current_known_ = 0;
    straight_s_ = 0;
    bow_known_ = 0;
    damp_on_ = 0;
    for (int i = 0; i < 4; ++i) {
        out_off_[i] = 0.0;
    }
    blend_m_rad_[0] = 0.0;
    blend_m_rad_[1] = 0.0;
    blend_window_ = 0;
    blend_on_ = 0;
    // a wander of 90 deg or more reads 1 (coarse_align::rotation_sine)
    coarse_wander_max_ = cfg.integrity_coarse_rad >= 0.5 * kPi ? 1.0 : pmath::sin(cfg.integrity_coarse_rad);

    // The IMU frame at t0: C_p^n = C_b^n C_p^b = C_b^n Rz(alpha).
    const Vec3 euler_b(cfg.euler_b_rad[0], cfg.euler_b_rad[1], cfg.euler_b_rad[2]);
    const Mat3 mat_np = attitude::euler_to_mat(euler_b) * attitude::rot_z(encoder_);
    strapdown::NavState nav;
    nav.lat = cfg.lat_rad;
    nav.lon = (cfg.lon_rad > kPi || cfg.lon_rad <= -kPi) ? wrap_pi(wrap_two_pi(cfg.lon_rad))
                                                        : cfg.lon_rad;
    nav.height = cfg.height_m;
    nav.vel_n = Vec3(cfg.vel_n_mps[0], cfg.vel_n_mps[1], cfg.vel_n_mps[2]);
    nav.quat_np = attitude::mat_to_quat(mat_np);
    const strapdown::Vertical vertical = cfg.vertical_mode == PYINS_VERTICAL_FREE
                                             ? strapdown::Vertical::kFree
                                             : strapdown::Vertical::kHold;
    sd_ = strapdown::make_strapdown(nav, vertical);

    if (cfg.coarse_ticks > 0) {
        coarse_align::Params prm;
        prm.method = cfg.coarse_method;
        prm.lever = has_lever_;
        prm.ratio = cfg.coarse_ratio;
        prm.first_output = cfg.coarse_first_output_ticks;
        prm.output_every = cfg.coarse_output_every_ticks;
        prm.dt = dt_;
        pmath::sincos(cfg.lat_rad, &prm.sin_lat, &prm.cos_lat);
        prm.gravity = earth::normal_gravity(prm.sin_lat, cfg.height_m);
        prm.settle_from = cfg.coarse_ticks - cfg.coarse_ticks / 5;
        prm.ref_gap_max = config::kCoarseRefGapS * cfg.tick_hz;
        const earth::PrincipalRadii radii = earth::principal_radii(prm.sin_lat);
        prm.rm_h = radii.rm + cfg.height_m;
        prm.rn_h = radii.rn + cfg.height_m;
        // the noise the static fine filters' R is built from, measured on
        // their update interval (coarse_align.hpp, "Noise")
        const bool static_fine = cfg.fine_ticks > 0 && fine_filter::static_base(cfg.fine_states);
        prm.noise_every = static_fine && cfg.fine_noise == PYINS_FINE_NOISE_MEASURED
                              ? cfg.fine_meas_every_ticks : 0;
        coarse_align::init(coarse_, prm);
    }
    indexing::Params& ip = index_prm_;
    if (cfg.index_scheme == PYINS_INDEX_CUSTOM) {
        ip.n_steps = cfg.index_n_steps;
        for (int32_t i = 0; i < cfg.index_n_steps; ++i) {
            ip.steps[i].stop_ticks = cfg.index_steps[i].stop_ticks;
            ip.steps[i].kind = static_cast<indexing::Kind>(cfg.index_steps[i].kind);
            ip.steps[i].angle = cfg.index_steps[i].angle_rad;
        }
    } else {
        ip.n_steps = indexing::preset_steps(cfg.index_scheme, cfg.index_stop_ticks, ip.steps);
    }
    ip.rate = cfg.index_rate_rad_s;
    ip.accel = cfg.index_accel_rad_s2;
    ip.delta = cfg.index_delta;
    ip.max_flex = cfg.index_max_flex_rad;
    ip.tolerance = cfg.index_tolerance_rad;
    ip.jump = cfg.index_jump_rad;
    ip.timeout_ticks = cfg.index_timeout_ticks;
    ip.sums = cfg.index_sums;
    ip.dt = dt_;
    ip.isolate = cfg.index_scheme == PYINS_INDEX_HEADING_ISOLATION ? 1 : 0;
    // Before NAVIGATE the table is held where it is (an idle machine, command 0).
    indexing::Params idle = ip;
    idle.n_steps = 0;
    indexing::init(idx_, idle, table_angle_);
    magic_ = kMagic;
}

void Firmware::start_navigation() {
    mode_ = Mode::kNavigate;
    indexing::init(idx_, index_prm_, table_angle_);
    if (cfg_.nav_mode != PYINS_NAV_UNDAMPED) {
        start_nav_filter();
    }
}


Quat Firmware::ship_quat() const {
    // q_nb = q_np q_pb, q_pb = [cos(alpha/2), 0, 0, -sin(alpha/2)]
    return attitude::quat_mul_z(sd_.nav.quat_np, enc_cos_half_, -enc_sin_half_);
}

void Firmware::bow_n(double* east, double* north, double* horizontal) const {
    // C_b^n = C_p^n C_b^p; its column 1 (the bow) is (C01, C11, C21)
    const Quat q_nb = ship_quat();
    const double c01 = 2.0 * (q_nb.x * q_nb.y - q_nb.w * q_nb.z);
    const double c11 = q_nb.w * q_nb.w - q_nb.x * q_nb.x + q_nb.y * q_nb.y - q_nb.z * q_nb.z;
    const double h = pmath::sqrt(c01 * c01 + c11 * c11);
    if (horizontal != nullptr) {
        *horizontal = h;
    }
    *east = 0.0;    // (a vertical bow: no horizontal direction)
    *north = 0.0;
    if (h > 0.0) {
        *east = c01 / h;
        *north = c11 / h;
    }
}

void Firmware::imu_yaw_sincos(double* sin_yaw_p, double* cos_yaw_p) const {
    // yaw of C_b^n = atan2(-C01, C11) (attitude::mat_to_euler): its cosine
    // and sine are the bow's north and minus its east component (no angle
    // taken; -(C01 / h) is -C01 / h bit for bit)
    double be;
    double bn;
    bow_n(&be, &bn);
    double cb = 1.0;   // atan2(0, 0) = 0: the yaw of a vertical x axis
    double sb = 0.0;
    if (be != 0.0 || bn != 0.0) {
        cb = bn;
        sb = -be;
    }
    // psi_p = psi_b + alpha by the angle sum
    double sa;
    double ca;
    encoder_sincos(&sa, &ca);
    *cos_yaw_p = cb * ca - sb * sa;
    *sin_yaw_p = sb * ca + cb * sa;
}

void Firmware::update_rates(const Vec3& dtheta_p, double dalpha) {
    // The increments are means over the tick; the rate at its end is
    // extrapolated from the last two (second order: the error is
    // (5/12) w'' dt^2, against w' dt / 2 for the tick's mean alone).
    if (rate_count_ == 0) {
        rate_p_ = dtheta_p / dt_;
        alpha_rate_ = dalpha / dt_;
    } else {
        rate_p_ = (1.5 * dtheta_p - 0.5 * prev_dtheta_) / dt_;
        alpha_rate_ = (1.5 * dalpha - 0.5 * prev_dalpha_) / dt_;
    }
    prev_dtheta_ = dtheta_p;
    prev_dalpha_ = dalpha;
    if (rate_count_ < 2) {
        rate_count_ = rate_count_ + 1;
    }
}

void Firmware::encoder_sincos(double* sin_alpha, double* cos_alpha) const {
    // from the cached half-angle: sin a = 2 s c, cos a = c^2 - s^2
    *sin_alpha = 2.0 * enc_sin_half_ * enc_cos_half_;
    *cos_alpha = enc_cos_half_ * enc_cos_half_ - enc_sin_half_ * enc_sin_half_;
}

Vec3 Firmware::b_in_p(const double* lb) const {
    // Rz(alpha)^T l, alpha = the encoder angle
    double sa;
    double ca;
    encoder_sincos(&sa, &ca);
    return Vec3(ca * lb[0] + sa * lb[1], -sa * lb[0] + ca * lb[1], lb[2]);
}

Vec3 Firmware::lever_b_in_p() const {
    return b_in_p(cfg_.lever_b_m);
}

Vec3 Firmware::gnss_lever_vel_p() const {
    // d/dt (C_p^i Rz^T l) in p: (w_ip^p - alpha' z) x Rz(alpha)^T gnss_lever_b, as lever_vel_for
    const Vec3 w_b = rate_p_ - Vec3(0.0, 0.0, alpha_rate_);
    return attitude::cross(w_b, b_in_p(cfg_.gnss_lever_b_m));
}

Vec3 Firmware::lever_p() const {
    return lever_b_in_p() + Vec3(cfg_.lever_p_m[0], cfg_.lever_p_m[1], cfg_.lever_p_m[2]);
}

Vec3 Firmware::lever_vel_p() const {
    return lever_vel_for(rate_p_, alpha_rate_);
}

Vec3 Firmware::lever_vel_for(const Vec3& rate_p, double alpha_rate) const {
    // u^p = (w_ip^p - alpha' z) x (Rz^T lever_b) + w_ip^p x lever_p: the table
    // centre moves with the ship (w_ib, in p), the sensor offset with the IMU.
    const Vec3 lp(cfg_.lever_p_m[0], cfg_.lever_p_m[1], cfg_.lever_p_m[2]);
    const Vec3 w_b = rate_p - Vec3(0.0, 0.0, alpha_rate);
    return attitude::cross(w_b, lever_b_in_p()) + attitude::cross(rate_p, lp);
}

Vec3 Firmware::lever_vel_e_n(const Mat3& mat_np) const {
    double sin_lat;
    double cos_lat;
    pmath::sincos(sd_.nav.lat, &sin_lat, &cos_lat);
    const Vec3 w_ie_n(0.0, earth::kOmegaIe * cos_lat, earth::kOmegaIe * sin_lat);
    return mat_np * lever_vel_p() - attitude::cross(w_ie_n, mat_np * lever_p());
}

void Firmware::place_imu(double lat, double lon, double height, const Vec3& vel_n) {
    // The accelerometers are at C_p^n r^p from the reference point (ENU
    // offset d, turned into latitude, longitude and height with the radii
    // there: second-order terms ~ |d|^2 / R < 1e-6 m for |d| < 100 m).
    const Mat3 mat_np = attitude::quat_to_mat(sd_.nav.quat_np);
    const Vec3 d = mat_np * lever_p();
    double sin_lat;
    double cos_lat;
    pmath::sincos(lat, &sin_lat, &cos_lat);
    const earth::PrincipalRadii r = earth::principal_radii(sin_lat);
    strapdown::NavState& nav = sd_.nav;
    nav.lat = lat + d(1) / (r.rm + height);
    nav.lon = wrap_pi(lon + d(0) / ((r.rn + height) * cos_lat));
    nav.height = height + d(2);
    nav.vel_n = vel_n + lever_vel_e_n(mat_np);
    if (sd_.vertical == strapdown::Vertical::kHold) {
        nav.vel_n(2) = 0.0;
        sd_.ref_height = nav.height;
    }
}

void Firmware::reference_point(double* lat, double* lon, double* height, Vec3* vel_n) const {
    const strapdown::NavState& nav = sd_.nav;
    const Mat3 mat_np = attitude::quat_to_mat(nav.quat_np);
    const Vec3 d = mat_np * lever_p();
    double sin_lat;
    double cos_lat;
    pmath::sincos(nav.lat, &sin_lat, &cos_lat);
    const earth::PrincipalRadii r = earth::principal_radii(sin_lat);
    *vel_n = nav.vel_n - lever_vel_e_n(mat_np);
    *lat = nav.lat - d(1) / (r.rm + nav.height);
    *lon = wrap_pi(nav.lon - d(0) / ((r.rn + nav.height) * cos_lat));
    *height = nav.height - d(2);
}

void Firmware::hold_static_base(Vec3* dv_sf_n) {
    hold_at_site();
    if (has_lever_ != 0) {
        // The lever arm's share of the specific force in n over the tick,
        // C_p^n (d/dt (C_p^i u^p)) = d/dt (C_p^n u^p) + w_ie^n x C_p^n u^p at
        // rest: the difference of its velocity telescopes, so no angular
        // acceleration is taken from the gyro.
        double sin_lat;
        double cos_lat;
        pmath::sincos(cfg_.lat_rad, &sin_lat, &cos_lat);
        const Vec3 w_ie_n(0.0, earth::kOmegaIe * cos_lat, earth::kOmegaIe * sin_lat);
        const Vec3 lv = attitude::quat_to_mat(sd_.nav.quat_np) * lever_vel_p();
        *dv_sf_n = *dv_sf_n - (lv - lever_vel_n_) - attitude::cross(w_ie_n, lv) * dt_;
        lever_vel_n_ = lv;
    }
}

void Firmware::fine_tick(const Vec3& dtheta_p, const Vec3& dv_p) {
    // The strapdown propagates the attitude. A static-base filter (seed 001)
    // has position and velocity held at the site and measures the specific
    // force in n; the moving-base one lets the horizontal channels run free
    // (vertical held) and measures, every meas_every ticks, the reference
    // point's offset from the site (moving_align.hpp).
    Vec3 dv_sf_n = strapdown::update(sd_, dtheta_p, dv_p, dt_);
    if (fine_.static_base()) {
        hold_static_base(&dv_sf_n);
    }
    double z[2] = {0.0, 0.0};
    if (fine_.measure()) {
        double lat = sd_.nav.lat;
        double lon = sd_.nav.lon;
        double height = sd_.nav.height;
        Vec3 vel = sd_.nav.vel_n;
        if (has_lever_ != 0) {
            reference_point(&lat, &lon, &height, &vel);
        }
        fine_.site_offset(lat, lon, cfg_.lat_rad, sd_.ref_lon, z);
    }
    const bool updated = fine_.step(dv_sf_n, z);
    if (!fine_.healthy()) {
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_KF_NOT_PD);
    }
    if (!fine_.consistent()) {
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_ALIGN_INCONSISTENT);
        integrity_lost_ = 1;
    }
    // The moving-base filter feeds back in both correction modes: its free
    // horizontal channels need their velocity and position corrected to
    // stay linear.
    if (updated && (!fine_.static_base() || cfg_.fine_correction == PYINS_FINE_FEEDBACK)) {
        apply_fine_correction();
    }
    fine_tick_ = fine_tick_ + 1;
    if (fine_tick_ == cfg_.fine_ticks) {
        end_fine();
    }
}

void Firmware::index_reset() {
    if (idx_.state == indexing::State::kFault) {
        indexing::reset(idx_, table_angle_);
    }
}

void Firmware::end_coarse() {
    // The next phase starts where the coarse alignment ends: the site
    // position, at rest, with the coarse attitude and the increment history
    // (so the coning terms continue without a gap). Under way: where the
    // references carried the reference point, at the last one's velocity
    // less its antenna's lever (coarse_align.hpp, "Under way").
    strapdown::NavState nav = sd_.nav;
    nav.vel_n = Vec3::Zero();
    nav.quat_np = attitude::mat_to_quat(coarse_align::mat_n_p(coarse_));
    double lat = cfg_.lat_rad;
    double lon = sd_.ref_lon;
    if (coarse_.prm.method == static_cast<int32_t>(coarse_align::Method::kFitVel)) {
        const int64_t since = coarse_.ref_tick < 0 ? coarse_.tick : coarse_.tick - coarse_.ref_tick;
        if (coarse_.ref_tick < 0 || coarse_.ref_gap > coarse_.prm.ref_gap_max ||
            since > coarse_.prm.ref_gap_max) {
            faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_ALIGN_INCONSISTENT);
            integrity_lost_ = 1;
        }
        lat = lat + coarse_.dlat;
        lon = wrap_pi(lon + coarse_.dlon);
        nav.lat = lat;
        nav.lon = lon;
        sd_.nav = nav;   // point_vel_n reads the latitude
        const Vec3 lever_v = point_vel_n(attitude::quat_mul_z(nav.quat_np, enc_cos_half_, -enc_sin_half_),
                                         cfg_.gnss_lever_b_m);
        nav.vel_n = Vec3(coarse_.ref_vel[0] - lever_v(0), coarse_.ref_vel[1] - lever_v(1), 0.0);
    }
    sd_ = strapdown::make_strapdown(nav, sd_.vertical);
    sd_.hist = coarse_.hist;
    if (has_lever_ != 0) {
        place_imu(lat, lon, cfg_.height_m, nav.vel_n);
    }
    att_valid_ = true;
    if (cfg_.fine_ticks > 0) {
        start_fine();
    } else {
        start_navigation();
    }
}

void Firmware::start_fine() {
    fine_filter::Params prm;
    fine_align::Params& base = prm.base;
    pmath::sincos(cfg_.lat_rad, &base.sin_lat, &base.cos_lat);
    base.gravity = earth::normal_gravity(base.sin_lat, cfg_.height_m);
    base.dt = dt_;
    base.meas_every = cfg_.fine_meas_every_ticks;
    base.gyro_arw = cfg_.fine_gyro_arw;
    base.accel_vrw = cfg_.fine_accel_vrw;
    base.sigma0_att[0] = cfg_.fine_sigma0_att_rad[0];
    base.sigma0_att[1] = cfg_.fine_sigma0_att_rad[1];
    base.sigma0_att[2] = cfg_.fine_sigma0_att_rad[2];
    base.sigma0_gyro = cfg_.fine_sigma0_gyro;
    base.sigma0_accel = cfg_.fine_sigma0_accel;
    base.nis_window = cfg_.integrity_nis_window > 0 ? cfg_.integrity_nis_window : 0;
    base.nis_max = cfg_.integrity_nis_max;
    const earth::PrincipalRadii r = earth::principal_radii(base.sin_lat);
    prm.rm_h = r.rm + cfg_.height_m;
    prm.rn_h = r.rn + cfg_.height_m;
    prm.pos_sigma = cfg_.fine_pos_sigma_m;
    prm.sigma0_vel = cfg_.fine_sigma0_vel_mps;
    prm.site_accel = cfg_.fine_site_accel;
    // what the coarse phase measured (fine_filter.hpp says what each filter takes)
    fine_filter::AfterCoarse after_coarse;
    if (cfg_.coarse_ticks > 0) {
        after_coarse.measured_vrw = coarse_align::measured_vrw(coarse_);
        after_coarse.seconds = static_cast<double>(cfg_.coarse_ticks) * dt_;
        after_coarse.wander = coarse_.wander;
    }
    fine_.init(cfg_.fine_states, prm, cfg_.coarse_ticks > 0 ? &after_coarse : nullptr);
    fine_tick_ = 0;
    if (has_lever_ != 0) {
        lever_vel_n_ = attitude::quat_to_mat(sd_.nav.quat_np) * lever_vel_p();
    }
    mode_ = Mode::kFineAlign;
}

Vec3 Firmware::fine_phi() const {
    if (mode_ != Mode::kFineAlign) {
        return Vec3::Zero();
    }
    return fine_.phi();
}

void Firmware::apply_fine_correction() {
    // C_p^n = (I + phi x) C_p^n': rotate the attitude by phi^ in n, then
    // phi^ = 0 (the error it described is gone).
    const Vec3 phi = fine_phi();
    const Quat q_phi = attitude::rotvec_to_quat(phi);
    sd_.nav.quat_np = attitude::quat_normalize(attitude::quat_mul(q_phi, sd_.nav.quat_np));
    if (has_lever_ != 0) {
        // the lever velocity in n turns with the attitude: else the next
        // tick's difference would read phi^ x C u as a specific force (a
        // feedback loop that turns 1' of heading into 40 ug and diverges)
        lever_vel_n_ = attitude::quat_to_mat(q_phi) * lever_vel_n_;
    }
    fine_.feedback(sd_.nav);
}

bool Firmware::fine_heading_known() const {
    return fine_.heading_variance() <= kValidHeadingSigma * kValidHeadingSigma;
}

bool Firmware::ref_aided() const {
    // a reference applied in navigation, or one met during the alignment
    // (skipped there): from the first navigation tick, no valid record on
    // the coarse attitude before the first fix arrives
    for (int i = 0; i < kRefKinds; ++i) {
        if (ref_seen_[i] != 0 || n_ref_skipped_[i] != 0u) {
            return true;
        }
    }
    return false;
}

bool Firmware::nav_heading_known() const {
    return nav_.p(nav_filter::kPhi + 2, nav_filter::kPhi + 2) <= kValidNavHeadingSigma * kValidNavHeadingSigma;
}

void Firmware::end_fine() {
    // Navigation starts from the corrected attitude (both correction modes);
    // a heading the filter does not know to kValidHeadingSigma is not valid
    // there either.
    if (!fine_heading_known()) {
        att_valid_ = false;
    }
    apply_fine_correction();
    if (has_lever_ != 0 && fine_.static_base()) {
        place_imu(cfg_.lat_rad, sd_.ref_lon, cfg_.height_m, Vec3::Zero());
    }
    start_navigation();
}

void Firmware::hold_at_site() {
    sd_.nav.lat = cfg_.lat_rad;
    sd_.nav.lon = sd_.ref_lon;
    sd_.nav.height = cfg_.height_m;
    sd_.nav.vel_n = Vec3::Zero();
    sd_.prev_dvel_n = Vec3::Zero();
    if (has_lever_ != 0) {
        place_imu(cfg_.lat_rad, sd_.ref_lon, cfg_.height_m, Vec3::Zero());
    }
}

void Firmware::reject(uint32_t fault_bit, uint32_t* counter) {
    faults_ = faults_ | fault_bit;
    count(counter, 1u);
    // Alignment cannot bridge a missing sample on a moving base (the
    // rotation over it is lost): it restarts at the next good sample.
    // Navigation only reports the rejection; its state is untouched.
    if (mode_ == Mode::kCoarseAlign || mode_ == Mode::kFineAlign) {
        gap_pending_ = true;
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_ALIGN_RESTARTED);
    }
}

SeqStep Firmware::seq_step(uint32_t seq) const {
    // d = seq - last seq taken, modulo 2^32 (serial-number arithmetic,
    // RFC 1982). 1: the next tick; 2..g+1: d-1 ticks missing; 0 or up to g
    // behind: a duplicate (a retransmission, overlapping logs); anything
    // else: the sequence broke (a long outage, an IMU restart).
    if (cfg_.seq_mode != PYINS_SEQ_CHECK || !seq_valid_) {
        return SeqStep{SeqKind::kNext, 0u};
    }
    const uint32_t d = seq - seq_;
    const uint32_t g = static_cast<uint32_t>(cfg_.seq_max_gap_ticks);
    if (d == 0u || d >= static_cast<uint32_t>(0u - g)) {
        return SeqStep{SeqKind::kRepeat, 0u};
    }
    if (d > g + 1u) {
        // a forward jump says how long the outage was; a backward one does not
        return SeqStep{SeqKind::kLost, d < 0x80000000u ? d - 1u : 0u};
    }
    if (d > 1u) {
        return SeqStep{SeqKind::kGap, d - 1u};
    }
    return SeqStep{SeqKind::kNext, 0u};
}

bool Firmware::usable(const pyins_sample& sample) const {
    // one pass: |v| < limit is false for a NaN and an infinity too
    return within(sample.dtheta_p_rad, cfg_.sat_gyro_rad) && within(sample.dv_p_mps, cfg_.sat_accel_mps) &&
           std::isfinite(sample.table_angle_rad);
}

int64_t Firmware::ticks_for(const pyins_sample& sample) const {
    if (!usable(sample)) {
        return 0;
    }
    const SeqStep seq = seq_step(sample.seq);
    return seq.kind == SeqKind::kRepeat ? 0 : static_cast<int64_t>(seq.missing) + 1;
}

int Firmware::reject_sample(const pyins_sample& sample, pyins_output* out) {
    if (!finite3(sample.dtheta_p_rad) || !finite3(sample.dv_p_mps) ||
        !std::isfinite(sample.table_angle_rad)) {
        reject(static_cast<uint32_t>(PYINS_FAULT_SAMPLE_NONFINITE), &counts_.nonfinite);
        if (out != nullptr) {
            output(out);
        }
        return PYINS_E_SAMPLE_NONFINITE;
    }
    // Finite, so beyond the IMU's range (the limits are finite and > 0):
    // the true increment is unknown (a shock) or the word is corrupted,
    // rejected like a non-finite one.
    reject(static_cast<uint32_t>(PYINS_FAULT_SAMPLE_SATURATED), &counts_.saturated);
    if (out != nullptr) {
        output(out);
    }
    return PYINS_E_SAMPLE_SATURATED;
}

int Firmware::step(const pyins_sample& sample, pyins_output* out) {
    // docs/core.md, "Sample-level faults": the checks in this order.
    // 1. Reject a non-finite sample, then a saturated one. A good sample
    //    passes both in one test (usable); only one that fails it is told apart.
    if (!usable(sample)) {
        return reject_sample(sample, out);
    }
    // 2. The sequence: drop a duplicate; note a gap or a resynchronisation.
    int status = PYINS_OK;
    const SeqStep seq = seq_step(sample.seq);
    if (seq.kind == SeqKind::kRepeat) {
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_SEQ_REPEAT);
        count(&counts_.seq_repeats, 1u);
        if (out != nullptr) {
            output(out);
        }
        return PYINS_W_SEQ_REPEAT;
    }
    const uint32_t missing = seq.missing;
    const bool resync = seq.kind == SeqKind::kLost;
    if (resync) {
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_SEQ_LOST);
        count(&counts_.seq_lost, 1u);
        status = PYINS_W_SEQ_LOST;
    } else if (seq.kind == SeqKind::kGap) {
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_SEQ_GAP);
        count(&counts_.seq_gaps, 1u);
        status = PYINS_W_SEQ_GAP;
    }
    // 3. The encoder reading, and its jump test.
    const Vec3 dtheta_p(sample.dtheta_p_rad[0], sample.dtheta_p_rad[1], sample.dtheta_p_rad[2]);
    const Vec3 dv_p(sample.dv_p_mps[0], sample.dv_p_mps[1], sample.dv_p_mps[2]);
    const double encoder = wrap_two_pi(sample.table_angle_rad);
    // Encoder jump: more than index_jump_rad per tick since the last reading
    // (over the ticks a gap spans). Not on the first sample (the configured
    // angle is a guess) nor after a resynchronisation (an outage of unknown
    // length). The reading is taken: the navigation of frame p does not use
    // it, and one tick cannot tell a glitch from a slipped encoder; the
    // indexing machine goes to FAULT (command 0) until pyins_index_reset.
    if (mode_ != Mode::kIdle && !resync && encoder_jumped(encoder, missing)) {
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_ENCODER_JUMP);
        count(&counts_.encoder_jumps, 1u);
        if (status == PYINS_OK) {
            status = PYINS_W_ENCODER_JUMP;
        }
    }
    // 4. Missing ticks: restart the alignment, skip them, or bridge them.
    if (missing > 0u || resync) {
        if (mode_ == Mode::kCoarseAlign || mode_ == Mode::kFineAlign) {
            // as for a rejected sample: the alignment restarts at this one
            gap_pending_ = true;
            faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_ALIGN_RESTARTED);
            tick_ = tick_ + static_cast<int64_t>(missing);
        } else if (resync) {
            // the motion of the outage is lost; time stays right when known
            tick_ = tick_ + static_cast<int64_t>(missing);
        } else {
            bridge(static_cast<int32_t>(missing), dtheta_p, dv_p, encoder);
            count(&counts_.seq_bridged, missing);
        }
    }
    // 5. This sample's tick, and the memory for the next one.
    take(sample.seq, dtheta_p, dv_p, encoder);
    if (out != nullptr) {
        output(out);
    }
    return status;
}

size_t Firmware::run_plain(const pyins_sample* samples, size_t n, int64_t tick_end, pyins_nav* navs) {
    if (mode_ != Mode::kNavigate || gap_pending_) {
        return 0u;
    }
    // one loop each: the test for a record is not in the loop without them
    return navs == nullptr ? plain_loop<false>(samples, n, tick_end, nullptr)
                           : plain_loop<true>(samples, n, tick_end, navs);
}

template <bool kNav>
size_t Firmware::plain_loop(const pyins_sample* samples, size_t n, int64_t tick_end, pyins_nav* navs) {
    size_t i = 0u;
    while (i < n && tick_ < tick_end) {
        // step()'s tests on a sample it takes as the next tick, in its order
        const pyins_sample& sample = samples[i];
        if (!usable(sample) || seq_step(sample.seq).kind != SeqKind::kNext) {
            break;
        }
        const double encoder = wrap_two_pi(sample.table_angle_rad);
        if (encoder_jumped(encoder, 0u)) {
            break;
        }
        const Vec3 dtheta_p(sample.dtheta_p_rad[0], sample.dtheta_p_rad[1], sample.dtheta_p_rad[2]);
        const Vec3 dv_p(sample.dv_p_mps[0], sample.dv_p_mps[1], sample.dv_p_mps[2]);
        take(sample.seq, dtheta_p, dv_p, encoder);
        if (kNav) {
            fill_nav(&navs[i]);
        }
        i = i + 1u;
    }
    return i;
}

bool Firmware::encoder_jumped(double encoder, uint32_t missing) const {
    return encoder != encoder_ &&
           std::fabs(wrap_pi(encoder - encoder_)) > cfg_.index_jump_rad * static_cast<double>(missing + 1u);
}

PYINS_HOT_INLINE void Firmware::take(uint32_t seq, const Vec3& dtheta_p, const Vec3& dv_p, double encoder) {
    advance(dtheta_p, dv_p, encoder);
    last_dtheta_ = dtheta_p;
    last_dv_ = dv_p;
    seq_ = seq;
    seq_valid_ = true;
}

void Firmware::bridge(int32_t missing, const Vec3& dtheta_p, const Vec3& dv_p, double encoder) {
    // Linear interpolation between the last sample taken and this one (the
    // missing ticks lie between them, and both are at hand when the gap is
    // seen): exact while the rate and specific force change linearly over
    // the gap, where repeating the last increments is exact only while they
    // are constant (docs/core.md, "Sample-level faults", measures both).
    // Uniform motion is bridged bit-exactly (the difference is 0).
    // (the last sample's increments are read in place: advance does not
    // change them, and copies would add 48 bytes to the deepest stack path)
    const Vec3& dtheta0 = last_dtheta_;
    const Vec3& dv0 = last_dv_;
    const Vec3 ddtheta = dtheta_p - dtheta0;
    const Vec3 ddv = dv_p - dv0;
    const double enc0 = encoder_;
    const double turn = wrap_pi(encoder - enc0);
    const double span = static_cast<double>(missing + 1);
    for (int32_t j = 1; j <= missing; ++j) {
        const double f = static_cast<double>(j) / span;
        const Vec3 dtheta_j = dtheta0 + ddtheta * f;
        const Vec3 dv_j = dv0 + ddv * f;
        advance(dtheta_j, dv_j, wrap_two_pi(enc0 + turn * f));
    }
}

PYINS_HOT_INLINE void Firmware::advance(const Vec3& dtheta_p, const Vec3& dv_p, double encoder) {
    // 1. Unwrap the encoder: the table turns far less than pi per tick.
    double dalpha = 0.0;
    if (encoder != encoder_) {  // the table moved: refresh the cached half-angle
        dalpha = wrap_pi(encoder - encoder_);
        encoder_ = encoder;
        pmath::sincos(0.5 * encoder_, &enc_sin_half_, &enc_cos_half_);
    }
    table_angle_ = table_angle_ + dalpha;
    // 2. Lever arm: w(t0) refined on the second tick, the rates of this one.
    if (has_lever_ != 0) {
        if (lever_refine_ != 0) {
            // Navigation started last tick from the configured reference
            // state with the first tick's mean rate for w(t0); with this
            // tick's increments w(t0) = (3 dth1 - dth2) / (2 dt): correct the
            // velocity (and the position it moved) by the difference.
            lever_refine_ = 0;
            const Vec3 dw = (prev_dtheta_ - dtheta_p) / (2.0 * dt_);
            const double dwa = (prev_dalpha_ - dalpha) / (2.0 * dt_);
            const Vec3 du = lever_vel_for(dw, dwa);   // u is linear in the rates
            Vec3 dvel = attitude::quat_to_mat(sd_.nav.quat_np) * du;
            if (sd_.vertical == strapdown::Vertical::kHold) {
                dvel(2) = 0.0;
            }
            double sin_lat;
            double cos_lat;
            pmath::sincos(sd_.nav.lat, &sin_lat, &cos_lat);
            const earth::PrincipalRadii r = earth::principal_radii(sin_lat);
            sd_.nav.vel_n = sd_.nav.vel_n + dvel;
            sd_.nav.lat = sd_.nav.lat + dvel(1) * dt_ / (r.rm + sd_.nav.height);
            sd_.nav.lon = wrap_pi(sd_.nav.lon + dvel(0) * dt_ / ((r.rn + sd_.nav.height) * cos_lat));
            if (sd_.vertical == strapdown::Vertical::kFree) {
                sd_.nav.height = sd_.nav.height + dvel(2) * dt_;
            }
        }
    }
    if (rates_on_ != 0) {
        update_rates(dtheta_p, dalpha);
    }
    // 3. An alignment restart (a sample rejected or missing) begins here.
    if (gap_pending_) {
        gap_pending_ = false;
        align_restarts_ = align_restarts_ + 1;
        if (cfg_.coarse_ticks > 0) {
            coarse_align::init(coarse_, coarse_.prm);
            att_valid_ = false;
            mode_ = Mode::kCoarseAlign;
        } else {
            start_fine();
        }
    }
    // 4. The first sample leaves IDLE for the first configured mode.
    if (mode_ == Mode::kIdle) {
        if (cfg_.coarse_ticks > 0) {
            mode_ = Mode::kCoarseAlign;
        } else if (cfg_.fine_ticks > 0) {
            start_fine();
        } else {
            start_navigation();
            if (has_lever_ != 0) {
                // the configured state is the reference point's at t0
                place_imu(cfg_.lat_rad, sd_.ref_lon, cfg_.height_m,
                          Vec3(cfg_.vel_n_mps[0], cfg_.vel_n_mps[1], cfg_.vel_n_mps[2]));
                lever_refine_ = 1;
            }
        }
    }
    // 5. The mode's work: coarse alignment, moving-base or static fine
    //    alignment, or navigation with the indexing cycle.
    if (mode_ == Mode::kCoarseAlign) {
        coarse_align::update(coarse_, dtheta_p, dv_p,
                             has_lever_ != 0 ? lever_vel_p() : Vec3::Zero(), gnss_lever_vel_p());
        // under way the noise's own wander is allowed (coarse_align.hpp, "Under way")
        double wander_max = coarse_wander_max_;
        const double noise_wander = coarse_align::kWanderSigmas * coarse_.settle_sigma;
        if (noise_wander >= 0.5 * kPi) {
            wander_max = 1.0;
        } else if (pmath::sin(noise_wander) > wander_max) {
            wander_max = pmath::sin(noise_wander);
        }
        if (coarse_.wander > wander_max) {
            faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_COARSE_UNSETTLED);
            integrity_lost_ = 1;
        }
        if (coarse_.tick == cfg_.coarse_ticks) {
            end_coarse();
        }
    } else if (mode_ == Mode::kFineAlign) {
        fine_tick(dtheta_p, dv_p);
    } else {
        if (nav_on_ != 0) {
            // the biases, scale factors and misalignments the filter
            // estimated, compensated (0 until it has)
            const Vec3 dtheta_c = nav_filter::compensate_gyro(nav_, dtheta_p, dt_);
            const Vec3 dv_sf_n = strapdown::update(sd_, dtheta_c, dv_p - nav_.accel_bias * dt_, dt_);
            nav_tick(dv_sf_n, dtheta_c);
            blend_tick();
        } else {
            strapdown::update(sd_, dtheta_p, dv_p, dt_);
        }
        if (index_prm_.n_steps > 0) {
            double sin_yaw_p = 0.0;
            double cos_yaw_p = 0.0;
            if (indexing::wants_heading(idx_)) {
                imu_yaw_sincos(&sin_yaw_p, &cos_yaw_p);
            }
            indexing::update(idx_, table_angle_, sin_yaw_p, cos_yaw_p);
        }
    }
    // 6. The tick, and the references that belong to it.
    tick_ = tick_ + 1;
    if (refq_count_ > 0) {
        refs_due();
    }
}

void Firmware::motor_command(pyins_motor_command* cmd) const {
    cmd->rate_rad_s = idx_.cmd_rate;
    cmd->angle_rad = idx_.cmd_angle;
    cmd->index_state = static_cast<int32_t>(idx_.state);
    cmd->index_fault = static_cast<int32_t>(idx_.fault);
}

PYINS_HOT_INLINE void Firmware::solution(double* lat, double* lon, double* height, double vel_n[3],
                                         double quat_np[4], double quat_nb[4], uint32_t* state_flags) const {
    const strapdown::NavState& nav = sd_.nav;
    if (has_lever_ != 0 && (mode_ == Mode::kFineAlign || mode_ == Mode::kNavigate)) {
        // The state is the accelerometers'; the record the reference point's.
        Vec3 vel;
        reference_point(lat, lon, height, &vel);
        vel_n[0] = vel(0);
        vel_n[1] = vel(1);
        // a held vertical channel holds the reference point too
        vel_n[2] = sd_.vertical == strapdown::Vertical::kHold ? 0.0 : vel(2);
    } else {
        *lat = nav.lat;
        *lon = nav.lon;
        *height = nav.height;
        vel_n[0] = nav.vel_n(0);
        vel_n[1] = nav.vel_n(1);
        vel_n[2] = nav.vel_n(2);
    }
    if (blend_on_ != 0 && mode_ == Mode::kNavigate) {
        // the bumpless return: the output offset (kBlendWindowS)
        *lat = *lat + out_off_[0];
        *lon = wrap_pi(*lon + out_off_[1]);
        vel_n[0] = vel_n[0] + out_off_[2];
        vel_n[1] = vel_n[1] + out_off_[3];
    }

    // Ship attitude: C_b^n = C_p^n C_b^p, C_b^p = Rz(-alpha), with alpha the
    // measured (encoder) angle: q_pb = [cos(alpha/2), 0, 0, -sin(alpha/2)].
    Quat q_np = nav.quat_np;
    bool valid = att_valid_;
    if (mode_ == Mode::kCoarseAlign && coarse_.solved) {
        q_np = attitude::mat_to_quat(coarse_align::mat_n_p(coarse_));
        // provisional: the coarse attitude is valid once the alignment has
        // ended and its wander test passed (a wrong solution can look
        // settled early in the test's window)
        valid = false;
    } else if (mode_ == Mode::kFineAlign) {
        // the best estimate: the propagated attitude corrected by phi^,
        // provisional until the first NIS window has passed
        q_np = attitude::quat_renormalize(
            attitude::quat_mul(attitude::rotvec_to_quat(fine_phi()), nav.quat_np));
        if ((cfg_.integrity_nis_window > 0 && fine_.nis_windows() == 0) || !fine_heading_known()) {
            valid = false;
        }
    } else if (mode_ == Mode::kNavigate && nav_on_ != 0 && fine_.states() == 0 && cfg_.coarse_ticks > 0 &&
               !nav_heading_known() && ref_aided()) {
        // the navigation filter started on the coarse attitude and aided
        // (an alignment in navigation: indexed, at anchor; after a fine
        // alignment its end decided, unaided the coarse one's): valid once
        // three times its heading sigma is within 10' (kValidNavHeadingSigma)
        valid = false;
    }
    *state_flags = valid && integrity_lost_ == 0 ? static_cast<uint32_t>(PYINS_STATE_ATT_VALID) : 0u;
    if (mode_ == Mode::kNavigate && (refs_in_use() & (1u << (PYINS_REF_GNSS_POS - 1))) != 0u) {
        *state_flags = *state_flags | static_cast<uint32_t>(PYINS_STATE_POS_AIDED);
    }
    const Quat q_nb = attitude::quat_renormalize(attitude::quat_mul_z(q_np, enc_cos_half_, -enc_sin_half_));
    quat_np[0] = q_np.w;
    quat_np[1] = q_np.x;
    quat_np[2] = q_np.y;
    quat_np[3] = q_np.z;
    quat_nb[0] = q_nb.w;
    quat_nb[1] = q_nb.x;
    quat_nb[2] = q_nb.y;
    quat_nb[3] = q_nb.z;
}

void Firmware::nav_record(pyins_nav* nav) const { fill_nav(nav); }

PYINS_HOT_INLINE void Firmware::fill_nav(pyins_nav* nav) const {
    nav->tick = tick_;
    nav->mode = static_cast<int32_t>(mode_);
    nav->fault_flags = faults_;
    nav->index_state = static_cast<int32_t>(idx_.state);
    nav->nav_mode = nav_mode_now();
    nav->ref_in_use = mode_ == Mode::kNavigate ? refs_in_use() : 0u;
    solution(&nav->lat_rad, &nav->lon_rad, &nav->height_m, nav->vel_n_mps, nav->quat_np, nav->quat_nb,
             &nav->state_flags);
    nav->table_angle_rad = table_angle_;
    nav->motor_rate_cmd_rad_s = idx_.cmd_rate;
    nav->table_angle_cmd_rad = idx_.cmd_angle;
}

void Firmware::output(pyins_output* out) const {
    out->tick = tick_;
    out->mode = static_cast<int32_t>(mode_);
    out->fault_flags = faults_;
    out->reserved0 = 0;
    solution(&out->lat_rad, &out->lon_rad, &out->height_m, out->vel_n_mps, out->quat_np, out->quat_nb,
             &out->state_flags);
    const Quat q_nb{out->quat_nb[0], out->quat_nb[1], out->quat_nb[2], out->quat_nb[3]};
    const Vec3 euler_b = attitude::quat_to_euler(q_nb);
    out->euler_b_rad[0] = euler_b(0);
    out->euler_b_rad[1] = euler_b(1);
    out->euler_b_rad[2] = euler_b(2);
    out->heading_b_rad = attitude::yaw_to_heading(euler_b(2));
    out->yaw_p_rad = wrap_pi(euler_b(2) + encoder_);
    out->table_angle_rad = table_angle_;
    out->index_state = static_cast<int32_t>(idx_.state);
    out->index_step = idx_.step;
    out->index_fault = static_cast<int32_t>(idx_.fault);
    out->index_fallbacks = idx_.fallbacks;
    out->motor_rate_cmd_rad_s = idx_.cmd_rate;
    out->table_angle_cmd_rad = idx_.cmd_angle;
    out->index_a_c = idx_.a_c;
    out->index_a_s = idx_.a_s;
    out->index_travel_rad = idx_.travel;
    out->index_motor_starts = idx_.motor_starts;
    out->reserved1 = 0;
    out->n_nonfinite = counts_.nonfinite;
    out->n_saturated = counts_.saturated;
    out->n_seq_gaps = counts_.seq_gaps;
    out->n_seq_bridged = counts_.seq_bridged;
    out->n_seq_repeats = counts_.seq_repeats;
    out->n_seq_lost = counts_.seq_lost;
    out->n_encoder_jumps = counts_.encoder_jumps;
    out->seq = seq_;
    out->align_nis = fine_.nis_mean();
    out->coarse_wander_rad = cfg_.coarse_ticks > 0 ? coarse_.wander : 0.0;
    out->coarse_vrw = cfg_.coarse_ticks > 0 ? coarse_align::measured_vrw(coarse_) : 0.0;
    out->fine_vrw = fine_.vrw();
    out->kf_states = fine_.states();
    out->align_restarts = align_restarts_;
    for (int i = 0; i < 8; ++i) {
        out->kf_x[i] = 0.0;
        out->kf_sigma[i] = 0.0;
    }
    fine_.record(out->kf_x, out->kf_sigma);
    out->nav_mode = nav_mode_now();
    out->ref_in_use = mode_ == Mode::kNavigate ? refs_in_use() : 0u;
    for (int32_t i = 0; i < kRefKinds; ++i) {
        out->n_ref_used[i] = n_ref_used_[i];
        out->n_ref_rejected[i] = n_ref_rejected_[i];
        out->n_ref_skipped[i] = n_ref_skipped_[i];
        out->n_ref_stale[i] = n_ref_stale_[i];
        out->nav_nis[i] = nav_nis_[i];
    }
    const bool filter = nav_on_ != 0;
    // the output's sigma: the filter's, and the output offset's distance
    // from its estimate while a return is blended (kBlendWindowS)
    double off2 = 0.0;
    if (blend_on_ != 0) {
        double de;
        double dn;
        blend_offset_m(&de, &dn);
        off2 = de * de + dn * dn;
    }
    out->nav_sigma_pos_m = filter ? pmath::sqrt(nav_.p(nav_filter::kPos, nav_filter::kPos) +
                                                nav_.p(nav_filter::kPos + 1, nav_filter::kPos + 1) + off2)
                                  : 0.0;
    out->nav_sigma_heading_rad = filter ? pmath::sqrt(nav_.p(nav_filter::kPhi + 2, nav_filter::kPhi + 2)) : 0.0;
    for (int i = 0; i < 4; ++i) {
        out->nav_level_err[i] = filter ? nav_.level_err[i] : 0.0;
    }
    for (int i = 0; i < 3; ++i) {
        out->nav_gyro_bias_rad_s[i] = filter ? nav_.gyro_bias(i) : 0.0;
        out->nav_table_err[i] = filter ? nav_.table_err(i) : 0.0;
        out->nav_accel_bias_mps2[i] = filter ? nav_.accel_bias(i) : 0.0;
    }
}

}  // namespace pyins::firmware
