// firmware_nav.cpp: the firmware at sea: the navigation filter beside the
// strapdown in NAVIGATE and the external references (pyins_push_ref: GNSS,
// the EM log's damping, the DVL's bottom track, zero velocity), the
// Firmware members firmware.hpp declares under "Navigation at sea".
// Mirrored by pyins/reference/firmware_nav.py; the filter is nav_filter.hpp.
#include <cmath>

#include "angle.hpp"
#include "attitude.hpp"
#include "coarse_align.hpp"
#include "config.hpp"
#include "earth.hpp"
#include "fine_align.hpp"
#include "firmware.hpp"
#include "math_portable.hpp"

namespace pyins::firmware {

using angle::wrap_pi;

void Firmware::start_nav_filter() {
    // The prior: the fine filter's attitude sigmas when one ran, else the
    // configured attitude sigmas (the defaults when left 0); the site's
    // position and the alignment's velocity residual (config.hpp).
    nav_filter::Params prm;
    prm.dt = dt_;
    prm.every = cfg_.nav_every_ticks;
    prm.reject_limit = cfg_.nav_reject_limit;
    prm.gyro_arw = cfg_.fine_gyro_arw;
    prm.accel_vrw = cfg_.fine_accel_vrw;
    prm.gate = cfg_.nav_gate;
    double kf_x[8] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    double kf_sigma[8] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    fine_.record(kf_x, kf_sigma);
    // (the defaults copied: the inline table's address is not taken, which
    // on the target would reach it through the global offset table)
    const double defaults[3] = {config::kDefaultFineSigmaAtt[0], config::kDefaultFineSigmaAtt[1],
                                config::kDefaultFineSigmaAtt[2]};
    // After a coarse alignment alone the sigmas the configuration left 0 are
    // fitted to the coarse result as the static fine filters' are
    // (fine_align::sigma0_after_coarse, seed 001 sec. 2, capped at the
    // defaults): 100', 100', 600' would let the first position fixes pull
    // the tilt about (1.7 m/s on the shipped real log with 3 m fixes).
    double fitted[3] = {cfg_.fine_sigma0_att_rad[0], cfg_.fine_sigma0_att_rad[1], cfg_.fine_sigma0_att_rad[2]};
    if (fine_.states() == 0 && cfg_.coarse_ticks > 0) {
        fine_align::Params fp{};
        pmath::sincos(cfg_.lat_rad, &fp.sin_lat, &fp.cos_lat);
        fp.gravity = earth::normal_gravity(fp.sin_lat, cfg_.height_m);
        fp.gyro_arw = cfg_.fine_gyro_arw;
        fp.accel_vrw = cfg_.fine_accel_vrw;
        const double measured = coarse_align::measured_vrw(coarse_);
        if (measured > fp.accel_vrw) {
            fp.accel_vrw = measured;
        }
        fp.sigma0_att[0] = fitted[0];
        fp.sigma0_att[1] = fitted[1];
        fp.sigma0_att[2] = fitted[2];
        fp.sigma0_gyro = cfg_.fine_sigma0_gyro;
        fp.sigma0_accel = cfg_.fine_sigma0_accel;
        fine_align::sigma0_after_coarse(fp, static_cast<double>(cfg_.coarse_ticks) * dt_, coarse_.wander, defaults);
        fitted[0] = fp.sigma0_att[0];
        fitted[1] = fp.sigma0_att[1];
        fitted[2] = fp.sigma0_att[2];
        if (coarse_.prm.method == static_cast<int32_t>(coarse_align::Method::kFitVel) &&
            cfg_.fine_sigma0_att_rad[2] == 0.0) {
            // under way the reference velocity's noise adds its heading sigma
            // (coarse_align.hpp, "Under way"), with the same margin
            const double h = fine_align::kAfterCoarseMargin * coarse_.sigma_heading;
            double v = pmath::sqrt(fitted[2] * fitted[2] + h * h);
            if (v > defaults[2]) {
                v = defaults[2];
            }
            fitted[2] = v;
        }
    }
    for (int i = 0; i < 3; ++i) {
        const double configured = fitted[i] > 0.0 ? fitted[i] : defaults[i];
        prm.sigma0_att[i] = fine_.states() != 0 ? kf_sigma[i] : configured;
    }
    prm.sigma0_vel = config::kNavSigma0Vel;
    prm.sigma0_pos = config::kNavSigma0Pos;
    prm.sigma0_gyro = cfg_.fine_sigma0_gyro;
    prm.sigma0_accel = cfg_.fine_sigma0_accel;
    prm.gyro_bias_rw = cfg_.nav_gyro_bias_rw;
    prm.table_scale = cfg_.nav_table_scale_sigma;
    prm.table_mis = cfg_.nav_table_mis_sigma;
    prm.level_scale = cfg_.nav_level_scale_sigma;
    prm.level_mis = cfg_.nav_level_mis_sigma;
    nav_filter::init(nav_, prm, attitude::quat_to_mat(sd_.nav.quat_np));
    nav_on_ = 1;
    for (int i = 0; i < 4; ++i) {
        out_off_[i] = 0.0;
    }
    blend_m_rad_[0] = 0.0;
    blend_m_rad_[1] = 0.0;
    blend_window_ = 0;
    blend_on_ = 0;
}

nav_filter::Motion Firmware::nav_motion() const {
    nav_filter::Motion m;
    pmath::sincos(sd_.nav.lat, &m.sin_lat, &m.cos_lat);
    const earth::PrincipalRadii r = earth::principal_radii(m.sin_lat);
    m.rm_h = r.rm + sd_.nav.height;
    m.rn_h = r.rn + sd_.nav.height;
    m.vel_e = sd_.nav.vel_n(0);
    m.vel_n = sd_.nav.vel_n(1);
    return m;
}

void Firmware::nav_tick(const Vec3& dv_sf_n, const Vec3& dtheta_c) {
    nav_filter::gather(nav_, dv_sf_n, dtheta_c);
    if (nav_.ticks == nav_.prm.every) {
        nav_filter::predict(nav_, nav_motion(), attitude::quat_to_mat(sd_.nav.quat_np));
        if (nav_.healthy == 0) {
            faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_KF_NOT_PD);
        }
        damp_interval();
    }
}

void Firmware::blend_offset_m(double* east, double* north) const {
    *east = out_off_[1] * blend_m_rad_[0];
    *north = out_off_[0] * blend_m_rad_[1];
}

void Firmware::blend_tick() {
    if (blend_window_ > 0) {
        blend_window_ = blend_window_ - 1;
    }
    if (blend_on_ == 0) {
        return;
    }
    // exponential decay over kBlendTau, the step capped at kBlendSpeed
    // (position) and kBlendAccel (velocity) times the tick
    const double a = dt_ / kBlendTau;
    double de;
    double dn;
    blend_offset_m(&de, &dn);
    const double d = pmath::sqrt(de * de + dn * dn);
    double sp = a;
    if (d * sp > kBlendSpeed * dt_) {
        sp = kBlendSpeed * dt_ / d;
    }
    const double v = pmath::sqrt(out_off_[2] * out_off_[2] + out_off_[3] * out_off_[3]);
    double sv = a;
    if (v * sv > kBlendAccel * dt_) {
        sv = kBlendAccel * dt_ / v;
    }
    out_off_[0] = out_off_[0] * (1.0 - sp);
    out_off_[1] = out_off_[1] * (1.0 - sp);
    out_off_[2] = out_off_[2] * (1.0 - sv);
    out_off_[3] = out_off_[3] * (1.0 - sv);
    if (d < kBlendDoneM && v < kBlendDoneMps) {
        for (int i = 0; i < 4; ++i) {
            out_off_[i] = 0.0;
        }
        blend_on_ = 0;
    }
}

int Firmware::push_ref(const pyins_ref& ref) {
    // UNDAMPED takes no reference; DAMPED no position (its position is
    // dead reckoning: a fix would be a reset, which is INTEGRATED's)
    if (cfg_.nav_mode == PYINS_NAV_UNDAMPED ||
        (cfg_.nav_mode == PYINS_NAV_DAMPED && ref.kind == PYINS_REF_GNSS_POS)) {
        return PYINS_E_REF_UNUSED;
    }
    // a DVL's reserved field marks its track: bottom track (0) alone is used
    const bool dvl = ref.kind == PYINS_REF_DVL;
    if ((ref.kind != PYINS_REF_GNSS_POS && ref.kind != PYINS_REF_GNSS_VEL && ref.kind != PYINS_REF_ZERO_VEL &&
         ref.kind != PYINS_REF_SPEED_LOG && !dvl) ||
        (dvl && ref.reserved != 0)) {
        return PYINS_E_REF_KIND;
    }
    // the vertical is held: sigma[2] is not used, nor checked, but by the
    // DVL (its axes are turned into n); the log uses component 0 alone
    const bool log = ref.kind == PYINS_REF_SPEED_LOG;
    if (!std::isfinite(ref.value[0]) || !std::isfinite(ref.value[1]) || !std::isfinite(ref.value[2]) ||
        !(ref.sigma[0] > 0.0) || !std::isfinite(ref.sigma[0]) ||
        (!log && (!(ref.sigma[1] > 0.0) || !std::isfinite(ref.sigma[1]))) ||
        (dvl && (!(ref.sigma[2] > 0.0) || !std::isfinite(ref.sigma[2]))) ||
        (ref.kind == PYINS_REF_GNSS_POS && !(std::fabs(ref.value[0]) <= 0.5 * kPi))) {
        return PYINS_E_REF_VALUE;
    }
    if (ref.tick < ref_last_tick_ || ref.tick < tick_ - static_cast<int64_t>(cfg_.ref_max_latency_ticks)) {
        return PYINS_E_REF_ORDER;
    }
    if (ref.tick > tick_ + static_cast<int64_t>(config::kRefHorizonS) * cfg_.tick_hz) {
        return PYINS_E_REF_FUTURE;
    }
    if (ref.tick > tick_) {
        if (refq_count_ == kRefQueue) {
            return PYINS_E_REF_FULL;
        }
        pyins_ref& slot = refq_[(refq_head_ + refq_count_) % kRefQueue];
        slot = ref;
        slot.reserved = 0;
        refq_count_ = refq_count_ + 1;
        ref_last_tick_ = ref.tick;
        return PYINS_OK;
    }
    // its tick has passed: now, the latency compensated
    ref_last_tick_ = ref.tick;
    if (mode_ == Mode::kNavigate && nav_on_ != 0) {
        apply_ref(ref, tick_ - ref.tick);
    } else {
        skip_ref(ref);
    }
    return PYINS_OK;
}

void Firmware::skip_ref(const pyins_ref& ref) {
    count(&n_ref_skipped_[ref.kind - 1], 1u);
    if (mode_ == Mode::kCoarseAlign && coarse_.prm.method == static_cast<int32_t>(coarse_align::Method::kFitVel)) {
        // under way: the velocity is the alignment's measurement, its tick
        // counted from the alignment's start (tick_ - coarse_.tick)
        if (ref.kind == PYINS_REF_GNSS_VEL) {
            const double sigma = ref.sigma[0] > ref.sigma[1] ? ref.sigma[0] : ref.sigma[1];
            // the vertical where the receiver measured one (sigma[2] > 0, finite)
            const double vu = ref.sigma[2] > 0.0 && std::isfinite(ref.sigma[2]) ? ref.value[2] : 0.0;
            coarse_align::reference(coarse_, ref.value[0], ref.value[1], vu, sigma,
                                    ref.tick - (tick_ - coarse_.tick));
        }
        return;
    }
    if ((mode_ != Mode::kCoarseAlign && mode_ != Mode::kFineAlign) ||
        (ref.kind != PYINS_REF_GNSS_VEL && ref.kind != PYINS_REF_DVL)) {
        return;
    }
    // The reference point's speed: GNSS's horizontal, the DVL's along its
    // three axes (bottom track: over ground; the heave's share is inside
    // the bound). The antenna or the DVL moves by w x l beyond it.
    const bool gnss = ref.kind == PYINS_REF_GNSS_VEL;
    const double* l = gnss ? cfg_.gnss_lever_b_m : cfg_.dvl_lever_b_m;
    double speed_sq = ref.value[0] * ref.value[0] + ref.value[1] * ref.value[1];
    double sigma = ref.sigma[0] > ref.sigma[1] ? ref.sigma[0] : ref.sigma[1];
    if (!gnss) {
        speed_sq = speed_sq + ref.value[2] * ref.value[2];
        sigma = sigma > ref.sigma[2] ? sigma : ref.sigma[2];
    }
    double lever_speed = 0.0;
    if (rates_on_ != 0) {
        const double w_sq = rate_p_(0) * rate_p_(0) + rate_p_(1) * rate_p_(1) + rate_p_(2) * rate_p_(2);
        lever_speed = pmath::sqrt(w_sq * (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]));
    }
    const double bound = config::kAlignMaxSpeed + 3.0 * sigma + lever_speed;
    if (speed_sq > bound * bound) {
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_ALIGN_INCONSISTENT);
        integrity_lost_ = 1;
    }
}

void Firmware::refs_due() {
    while (refq_count_ > 0 && refq_[refq_head_].tick <= tick_) {
        const pyins_ref& ref = refq_[refq_head_];
        if (mode_ == Mode::kNavigate && nav_on_ != 0) {
            apply_ref(ref, tick_ - ref.tick);
        } else {
            skip_ref(ref);
        }
        refq_head_ = (refq_head_ + 1) % kRefQueue;
        refq_count_ = refq_count_ - 1;
    }
}

void Firmware::reject_ref(int32_t slot) {
    count(&n_ref_rejected_[slot], 1u);
    if (ref_reject_run_[slot] < cfg_.nav_reject_limit) {
        ref_reject_run_[slot] = ref_reject_run_[slot] + 1;
    }
    if (ref_reject_run_[slot] == cfg_.nav_reject_limit) {
        ref_out_[slot] = 1;
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_REF_REJECTED);
    }
}

void Firmware::use_ref(int32_t slot) {
    ref_reject_run_[slot] = 0;
    ref_out_[slot] = 0;
    count(&n_ref_used_[slot], 1u);
    ref_used_tick_[slot] = tick_;
}

void Firmware::ref_point_vel(double* east, double* north) const {
    Vec3 vel = sd_.nav.vel_n;
    if (has_lever_ != 0) {
        double lat;
        double lon;
        double height;
        reference_point(&lat, &lon, &height, &vel);
    }
    *east = vel(0);
    *north = vel(1);
}

void Firmware::apply_log(const pyins_ref& ref, int32_t slot) {
    // The EM log: speed through water along the bow, v_log. A damping
    // reference, not a filter measurement: the ground velocity it stands for
    // is v_h b + c, v_h the reading's horizontal part (below), b the bow's
    // horizontal direction, c the current (and
    // the ship's sideslip) learnt where the velocity is known.
    double be;
    double bn;
    double hb;
    bow_n(&be, &bn, &hb);
    // The log reads the water's velocity along the hull's fore-aft axis,
    // which pitches: v_x = v_h cos(theta) + v_z sin(theta). Its horizontal
    // part is v_x / cos(theta), cos(theta) the bow's horizontal length by
    // the INS's own attitude; the vertical share v_z tan(theta) (heave at
    // the waves' pitch) averages out. Uncompensated, 2.8 deg of pitch swing
    // reads 0.12 % low (7 mm/s at 12 kn: 0.6 km a day along the track,
    // docs/results/damping_72h.md).
    if (!(hb > kLogMinHorizontal)) {
        reject_ref(slot);
        return;
    }
    double ve;
    double vn;
    ref_point_vel(&ve, &vn);
    const double v_h = ref.value[0] / hb;
    if (current_known_ == 0) {
        // the first reading: the velocity now stands for the current (the
        // gate's reference until the mean is made)
        current_n_[0] = ve - v_h * be;
        current_n_[1] = vn - v_h * bn;
    }
    // gate: the innovation along the bow against the log's sigma and the
    // filter's velocity variance there (chi-square, 1 degree of freedom,
    // tested against nav_gate)
    const double innov = (ve - current_n_[0]) * be + (vn - current_n_[1]) * bn - v_h;
    const int32_t kv = nav_filter::kVel;
    const double pvv = nav_.p(kv, kv) * be * be + 2.0 * nav_.p(kv, kv + 1) * be * bn + nav_.p(kv + 1, kv + 1) * bn * bn;
    const double nis = innov * innov / (ref.sigma[0] * ref.sigma[0] + pvv);
    nav_nis_[slot] = nis;
    if (!(nis <= cfg_.nav_gate)) {   // a NaN fails too
        reject_ref(slot);
        return;
    }
    use_ref(slot);
    log_speed_ = v_h;
    // the current: the mean of the first kCurrentReadings readings, then a
    // low-pass while the velocity is known (GNSS velocity or zero velocity
    // or a DVL's bottom track in use), else held (firmware.hpp)
    const uint32_t known =
        (1u << (PYINS_REF_GNSS_VEL - 1)) | (1u << (PYINS_REF_DVL - 1)) | (1u << (PYINS_REF_ZERO_VEL - 1));
    double n = static_cast<double>(kCurrentReadings);
    if (current_known_ < kCurrentReadings) {
        current_known_ = current_known_ + 1;
        n = static_cast<double>(current_known_);
    } else if ((refs_in_use() & known) == 0u) {
        return;
    }
    current_n_[0] = current_n_[0] + (ve - v_h * be - current_n_[0]) / n;
    current_n_[1] = current_n_[1] + (vn - v_h * bn - current_n_[1]) / n;
}

Vec3 Firmware::point_vel_n(const Quat& q_nb, const double* l) const {
    // A point at the lever arm l (reference point -> the point, in b) moves
    // C_b^n (w_eb^b x l) = C_b^n (w_ib^b x l) - w_ie^n x C_b^n l faster than
    // the reference point (the Earth-referenced velocity of a lever arm,
    // Groves 2013 ch. 14's velocity measurement), w_ib^b = C_p^b (w_ip^p -
    // alpha' z) from the rates at the end of this tick (update_rates), C_p^b
    // = Rz(alpha).
    double sa;
    double ca;
    encoder_sincos(&sa, &ca);
    const Vec3 w_p = rate_p_ - Vec3(0.0, 0.0, alpha_rate_);
    const Vec3 w_b(ca * w_p(0) - sa * w_p(1), sa * w_p(0) + ca * w_p(1), w_p(2));
    const Mat3 c_nb = attitude::quat_to_mat(q_nb);
    const Vec3 lb(l[0], l[1], l[2]);
    double sin_lat;
    double cos_lat;
    pmath::sincos(sd_.nav.lat, &sin_lat, &cos_lat);
    const Vec3 w_ie_n(0.0, earth::kOmegaIe * cos_lat, earth::kOmegaIe * sin_lat);
    return c_nb * attitude::cross(w_b, lb) - attitude::cross(w_ie_n, c_nb * lb);
}

void Firmware::dvl_n(const pyins_ref& ref, double v_n[2], double r[2]) const {
    // The DVL, bottom track: the velocity over ground of the DVL's point, in
    // its own frame d (Groves 2013, ch. 6, Doppler radar and sonar), turned
    // into n with the INS's own attitude, v = C_b^n C_d^b v_d (C_b^n = C_p^n
    // C_b^p from the IMU's attitude and the table angle, as bow_n; C_d^b =
    // exp([m x]), m = dvl_align_rad), and used as a reference velocity: the
    // loosely coupled velocity update (Groves 2013, ch. 14 and ch. 16 for a
    // dead-reckoning sensor aiding an INS: the measurement is the difference
    // of the two velocities in n; H = unit rows on dv_E, dv_N). Not
    // modelled: the attitude error's share of the turned velocity, v x phi
    // (1' of heading at 8 m/s is 2.3 mm/s; with it H would have v's columns
    // on phi), the DVL's scale factor and the mounting left after
    // calibration (not states: they pass into the velocity, and the position
    // drifts by the scale factor times the distance made good along the
    // track, the misalignment about z times it across), the vertical
    // component (the vertical channel is held), a reading's latency (the
    // velocity is not carried forward, as GNSS velocity's is not).
    const Quat q_nb = ship_quat();
    const double* m = cfg_.dvl_align_rad;
    const Quat q_bd = attitude::rotvec_to_quat(Vec3(m[0], m[1], m[2]));
    const Mat3 c_nd = attitude::quat_to_mat(attitude::quat_mul(q_nb, q_bd));
    Vec3 v = c_nd * Vec3(ref.value[0], ref.value[1], ref.value[2]);
    const double* l = cfg_.dvl_lever_b_m;
    if (l[0] != 0.0 || l[1] != 0.0 || l[2] != 0.0) {
        // the DVL moves point_vel_n faster than the reference point
        v = v - point_vel_n(q_nb, l);
    }
    v_n[0] = v(0);
    v_n[1] = v(1);
    // R = C_d^n diag(sigma^2) C_n^d, its E and N variances; the covariance
    // between them is left out (the filter's R is diagonal): it is 0 when
    // sigma_x = sigma_y and the DVL is level, and small beside them under a
    // few degrees of roll and pitch unless sigma_z is much the larger
    const double s0 = ref.sigma[0] * ref.sigma[0];
    const double s1 = ref.sigma[1] * ref.sigma[1];
    const double s2 = ref.sigma[2] * ref.sigma[2];
    for (int i = 0; i < 2; ++i) {
        r[i] = c_nd(i, 0) * c_nd(i, 0) * s0 + c_nd(i, 1) * c_nd(i, 1) * s1 + c_nd(i, 2) * c_nd(i, 2) * s2;
    }
}

void Firmware::damp_interval() {
    const double t = static_cast<double>(nav_.prm.every) * dt_;
    double be;
    double bn;
    bow_n(&be, &bn);
    // the course's turn rate: the bow's rotation over the interval (its sine),
    // low-passed over kTurnTau
    if (bow_known_ != 0) {
        const double rate = (bow_last_[1] * be - bow_last_[0] * bn) / t;
        turn_rate_f_ = turn_rate_f_ + (rate - turn_rate_f_) * (t / kTurnTau);
    }
    bow_last_[0] = be;
    bow_last_[1] = bn;
    bow_known_ = 1;
    if (std::fabs(turn_rate_f_) < kStraightRate) {
        if (straight_s_ < kStraightS) {
            straight_s_ = straight_s_ + 1;
        }
    } else {
        straight_s_ = 0;
    }
    damp_on_ = nav_mode_now() == PYINS_NAV_DAMPED ? 1 : 0;
    if (damp_on_ == 0) {
        return;
    }
    // Level damping: a third-order network on each horizontal channel
    // (the classic marine damping of the Schuler loop; Qin 2014, ch. 5;
    // Titterton & Weston 2004, sec. 12.3). With e = v - v_ref, the north
    // channel's errors (ENU, Qin 2014 eq. 4.2.15: dv_N' = g phi_E,
    // phi_E' = -dv_N / R + eps_E) gain
    //   dv_N'  -= K1 e_N
    //   phi_E' -= (K2 e_N + K3 int e_N) / R
    // (the east channel alike, phi_N' += ...), so that
    //   s^3 + K1 s^2 + w_s^2 (1 + K2) s + w_s^2 K3
    //     = (s + w_s)(s^2 + 2 zeta w_s s + w_s^2):
    //   K1 = (1 + 2 zeta) w_s,  K2 = 2 zeta,  K3 = w_s,
    // and a constant gyro drift leaves no steady velocity error (the
    // integrator holds R eps). Applied once an interval t: the velocity
    // less K1 t e, the attitude turned by the phi change (C <- (I - dphi x) C:
    // the rotation by -dphi), the integrators plus K3 t e.
    const nav_filter::Motion m = nav_motion();
    const double g = earth::normal_gravity(m.sin_lat, sd_.nav.height);
    const double w_s = pmath::sqrt(g / pmath::sqrt(m.rm_h * m.rn_h));
    const double k1 = (1.0 + 2.0 * kDampingRatio) * w_s;
    const double k2 = 2.0 * kDampingRatio;
    const double k3 = w_s;
    double ve;
    double vn;
    ref_point_vel(&ve, &vn);
    // v_ref: the log's v_h b + c, or the damping reference's (damp_ref_kind)
    const int32_t kind = damp_ref_kind();
    double re = log_speed_ * be + current_n_[0];
    double rn = log_speed_ * bn + current_n_[1];
    if (kind != PYINS_REF_SPEED_LOG) {
        re = damp_ref_[kind - 1][0];
        rn = damp_ref_[kind - 1][1];
    }
    const double e_e = ve - re;
    const double e_n = vn - rn;
    damp_int_[0] = damp_int_[0] + k3 * t * e_e;
    damp_int_[1] = damp_int_[1] + k3 * t * e_n;
    const Vec3 dphi(-(k2 * e_n + damp_int_[1]) * t / m.rm_h, (k2 * e_e + damp_int_[0]) * t / m.rn_h, 0.0);
    strapdown::NavState& nav = sd_.nav;
    nav.quat_np = attitude::quat_normalize(attitude::quat_mul(attitude::rotvec_to_quat(-dphi), nav.quat_np));
    nav.vel_n(0) = nav.vel_n(0) - k1 * t * e_e;
    nav.vel_n(1) = nav.vel_n(1) - k1 * t * e_n;
}

void Firmware::apply_ref(const pyins_ref& ref, int64_t lag) {
    const int32_t slot = ref.kind - 1;
    if (ref.kind == PYINS_REF_SPEED_LOG) {
        apply_log(ref, slot);
        return;
    }
    const nav_filter::Motion m = nav_motion();
    // the time update up to this tick first
    nav_filter::predict(nav_, m, attitude::quat_to_mat(sd_.nav.quat_np));
    double lat = sd_.nav.lat;
    double lon = sd_.nav.lon;
    double height = sd_.nav.height;
    Vec3 vel = sd_.nav.vel_n;
    if (has_lever_ != 0) {
        reference_point(&lat, &lon, &height, &vel);
    }
    // The GNSS antenna at gnss_lever_b_m: its fixes are compared with the
    // antenna's position, the reference point's plus C_b^n l, and velocity,
    // plus point_vel_n (Groves 2013 ch. 14, the lever arm of a loosely
    // coupled GNSS/INS; the attitude error's share, (C_b^n l) x phi, is not
    // a row of H: 1' on a 25 m mast is 7 mm)
    const double* la = cfg_.gnss_lever_b_m;
    const bool antenna = (ref.kind == PYINS_REF_GNSS_POS || ref.kind == PYINS_REF_GNSS_VEL) &&
                         (la[0] != 0.0 || la[1] != 0.0 || la[2] != 0.0);
    Vec3 ant_n = Vec3::Zero();
    const Vec3 vel_rp = vel;
    if (antenna) {
        const Quat q_nb = ship_quat();
        ant_n = attitude::quat_to_mat(q_nb) * Vec3(la[0], la[1], la[2]);
        vel = vel + point_vel_n(q_nb, la);
    }
    // z = computed - reference, on the unit rows of dp or dv
    double z[2];
    double r[2] = {ref.sigma[0] * ref.sigma[0], ref.sigma[1] * ref.sigma[1]};
    int k = nav_filter::kVel;
    if (ref.kind == PYINS_REF_GNSS_POS) {
        // carried to this tick by the velocity over the latency
        const double lag_s = static_cast<double>(lag) * dt_;
        z[0] = wrap_pi(lon - ref.value[1]) * m.rn_h * m.cos_lat - vel(0) * lag_s;
        z[1] = (lat - ref.value[0]) * m.rm_h - vel(1) * lag_s;
        if (antenna) {
            z[0] = z[0] + ant_n(0);
            z[1] = z[1] + ant_n(1);
        }
        k = nav_filter::kPos;
    } else if (ref.kind == PYINS_REF_GNSS_VEL) {
        z[0] = vel(0) - ref.value[0];
        z[1] = vel(1) - ref.value[1];
    } else if (ref.kind == PYINS_REF_DVL) {
        // a velocity pair like GNSS velocity's, from the DVL's axes (dvl_n)
        double v_dvl[2];
        dvl_n(ref, v_dvl, r);
        z[0] = vel(0) - v_dvl[0];
        z[1] = vel(1) - v_dvl[1];
    } else {
        z[0] = vel(0);
        z[1] = vel(1);
    }
    const double nis = nav_filter::nis_pair(nav_, k, z, r);
    nav_nis_[slot] = nis;
    // A frozen receiver repeats its last fix bit for bit: a repeat carries no
    // new information and is not used (applied, a frozen velocity would pull
    // the INS with it and a correlated error would pass as white noise). A
    // real receiver moving does not repeat (its noise moves the digits); at
    // rest, or cruising with a quantised NMEA speed, it may: a repeat counts
    // as rejected only when the ship moved more than 3 sigma since the first
    // copy (position: the distance at the speed now; velocity: the change of
    // the velocity). Zero velocity is the same value by design.
    bool stale = false;
    const bool repeat = ref.kind != PYINS_REF_ZERO_VEL && ref_seen_[slot] != 0 &&
                        ref.value[0] == ref_seen_value_[slot][0] && ref.value[1] == ref_seen_value_[slot][1];
    if (repeat) {
        const double sigma = ref.sigma[0] > ref.sigma[1] ? ref.sigma[0] : ref.sigma[1];
        double moved;
        if (ref.kind == PYINS_REF_GNSS_POS) {
            const double span = static_cast<double>(ref.tick - ref_seen_tick_[slot]) * dt_;
            moved = pmath::sqrt(vel(0) * vel(0) + vel(1) * vel(1)) * span;
        } else {
            const double de = vel(0) - ref_seen_vel_[slot][0];
            const double dn = vel(1) - ref_seen_vel_[slot][1];
            moved = pmath::sqrt(de * de + dn * dn);
        }
        stale = moved > 3.0 * sigma;
    }
    if (!repeat) {
        // (a repeat keeps the first copy's tick and velocity: the freeze's start)
        ref_seen_[slot] = 1;
        ref_seen_tick_[slot] = ref.tick;
        ref_seen_value_[slot][0] = ref.value[0];
        ref_seen_value_[slot][1] = ref.value[1];
        ref_seen_vel_[slot][0] = vel(0);
        ref_seen_vel_[slot][1] = vel(1);
    }
    if (repeat) {
        count(&n_ref_stale_[slot], 1u);
        if (!stale) {
            return;
        }
    }
    if (stale || !(nis <= cfg_.nav_gate)) {   // a NaN fails too
        reject_ref(slot);
        return;
    }
    use_ref(slot);
    if (cfg_.nav_mode == PYINS_NAV_DAMPED) {
        // a damping reference, not a filter measurement: the reference
        // point's ground velocity it stands for (z = computed - reference,
        // the antenna's velocity less its lever arm's share)
        damp_ref_[slot][0] = vel_rp(0) - z[0];
        damp_ref_[slot][1] = vel_rp(1) - z[1];
        return;
    }
    nav_filter::update_pair(nav_, k, z, r);
    if (nav_.healthy == 0) {
        faults_ = faults_ | static_cast<uint32_t>(PYINS_FAULT_KF_NOT_PD);
    }
    // Feedback (nav_filter.hpp): C_p^n = (I + phi x) C_p^n', v -= dv, p -= dp.
    const double* x = nav_.x.data();
    const Vec3 phi(x[nav_filter::kPhi], x[nav_filter::kPhi + 1], x[nav_filter::kPhi + 2]);
    strapdown::NavState& nav = sd_.nav;
    nav.quat_np = attitude::quat_normalize(attitude::quat_mul(attitude::rotvec_to_quat(phi), nav.quat_np));
    nav.vel_n(0) = nav.vel_n(0) - x[nav_filter::kVel];
    nav.vel_n(1) = nav.vel_n(1) - x[nav_filter::kVel + 1];
    nav.lat = nav.lat - x[nav_filter::kPos + 1] / m.rm_h;
    nav.lon = wrap_pi(nav.lon - x[nav_filter::kPos] / (m.rn_h * m.cos_lat));
    // a correction that would be a jump opens the window (kBlendMinM)
    const double dp = pmath::sqrt(x[nav_filter::kPos] * x[nav_filter::kPos] +
                                  x[nav_filter::kPos + 1] * x[nav_filter::kPos + 1]);
    const double dv = pmath::sqrt(x[nav_filter::kVel] * x[nav_filter::kVel] +
                                  x[nav_filter::kVel + 1] * x[nav_filter::kVel + 1]);
    if (dp > kBlendMinM || dv > kBlendMinMps) {
        blend_window_ = kBlendWindowS * cfg_.tick_hz;
    }
    if (blend_window_ > 0) {
        // the output stays where it was: the correction goes into its offset
        out_off_[0] = out_off_[0] + x[nav_filter::kPos + 1] / m.rm_h;
        out_off_[1] = out_off_[1] + x[nav_filter::kPos] / (m.rn_h * m.cos_lat);
        out_off_[2] = out_off_[2] + x[nav_filter::kVel];
        out_off_[3] = out_off_[3] + x[nav_filter::kVel + 1];
        blend_m_rad_[0] = m.rn_h * m.cos_lat;
        blend_m_rad_[1] = m.rm_h;
        blend_on_ = 1;
    }
    nav_filter::reset_feedback(nav_);
    nav_.c_start = attitude::quat_to_mat(nav.quat_np);
}

int32_t Firmware::nav_mode_now() const {
    if (mode_ != Mode::kNavigate) {
        return 0;
    }
    if (cfg_.nav_mode == PYINS_NAV_DAMPED) {
        return damp_ref_kind() != 0 ? static_cast<int32_t>(PYINS_NAV_DAMPED)
                                    : static_cast<int32_t>(PYINS_NAV_UNDAMPED);
    }
    const uint32_t in_use = nav_on_ != 0 ? refs_in_use() : 0u;
    const uint32_t log = 1u << (PYINS_REF_SPEED_LOG - 1);
    if ((in_use & ~log) != 0u) {
        return static_cast<int32_t>(PYINS_NAV_INTEGRATED);
    }
    // the log alone, on a straight course: damped (the position is dead reckoning)
    if ((in_use & log) != 0u && straight_s_ >= kStraightS && current_known_ >= kCurrentReadings) {
        return static_cast<int32_t>(PYINS_NAV_DAMPED);
    }
    return static_cast<int32_t>(PYINS_NAV_UNDAMPED);
}

int32_t Firmware::damp_ref_kind() const {
    // The classic marine override order (docs/concepts.md, "At sea"): the
    // reference velocity of a level-damped INS taken from GNSS, else the
    // EM log, else the DVL's bottom track, else zero velocity. The log
    // damps only on a straight course with the current learnt (a turn's
    // sideslip biases it; the current is what turns speed through water
    // into velocity over ground).
    const uint32_t in_use = nav_on_ != 0 ? refs_in_use() : 0u;
    const int32_t order[4] = {PYINS_REF_GNSS_VEL, PYINS_REF_SPEED_LOG, PYINS_REF_DVL, PYINS_REF_ZERO_VEL};
    for (int32_t i = 0; i < 4; ++i) {
        const int32_t kind = order[i];
        if ((in_use & (1u << (kind - 1))) == 0u) {
            continue;
        }
        if (kind == PYINS_REF_SPEED_LOG && (straight_s_ < kStraightS || current_known_ < kCurrentReadings)) {
            continue;
        }
        return kind;
    }
    return 0;
}

uint32_t Firmware::refs_in_use() const {
    uint32_t bits = 0u;
    const int64_t window = static_cast<int64_t>(kRefInUseS) * cfg_.tick_hz;
    for (int32_t i = 0; i < kRefKinds; ++i) {
        if (ref_used_tick_[i] >= 0 && tick_ - ref_used_tick_[i] <= window && ref_out_[i] == 0) {
            bits = bits | (1u << i);
        }
    }
    return bits;
}

}  // namespace pyins::firmware
