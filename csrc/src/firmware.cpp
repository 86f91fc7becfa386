// firmware.cpp: see firmware.hpp. Mirrored by pyins/reference/firmware.py.
#include "firmware.hpp"

#include <cmath>

#include "attitude.hpp"
#include "earth.hpp"
#include "math_portable.hpp"

namespace pyins::firmware {

using earth::kPi;
using earth::kTwoPi;

namespace {

bool finite3(const double v[3]) {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

/// Angle in [0, 2 pi). std::floor is exact, so this is bit-portable.
double wrap_two_pi(double a) {
    if (a >= 0.0 && a < kTwoPi) {
        return a;
    }
    double w = a - kTwoPi * std::floor(a / kTwoPi);
    if (w >= kTwoPi) {
        w = 0.0;
    }
    return w;
}

/// Angle in (-pi, pi] for an input within (-3 pi, 3 pi].
double wrap_pi(double a) {
    if (a > kPi) {
        return a - kTwoPi;
    }
    if (a <= -kPi) {
        return a + kTwoPi;
    }
    return a;
}

}  // namespace

void config_default(pyins_config* cfg) {
    *cfg = pyins_config{};
    cfg->tick_hz = kDefaultTickHz;
    cfg->vertical_mode = PYINS_VERTICAL_HOLD;
}

pyins_config config_resolved(const pyins_config& in) {
    pyins_config cfg = in;
    if (cfg.tick_hz == 0) {
        cfg.tick_hz = kDefaultTickHz;
    }
    if (cfg.coarse_first_output_ticks == 0) {
        cfg.coarse_first_output_ticks = kDefaultCoarseFirstS * cfg.tick_hz;
    }
    if (cfg.coarse_output_every_ticks == 0) {
        cfg.coarse_output_every_ticks = kDefaultCoarseEveryS * cfg.tick_hz;
    }
    if (cfg.coarse_ratio == 0.0) {
        cfg.coarse_ratio = kDefaultCoarseRatio;
    }
    return cfg;
}

int config_check(const pyins_config& raw) {
    if (raw.tick_hz < 0 || raw.tick_hz > kMaxTickHz) {
        return PYINS_E_CONFIG_RATE;
    }
    const pyins_config cfg = config_resolved(raw);
    if (!std::isfinite(cfg.lat_rad) || std::fabs(cfg.lat_rad) > kMaxLatRad) {
        return PYINS_E_CONFIG_LAT;
    }
    if (!std::isfinite(cfg.lon_rad) || std::fabs(cfg.lon_rad) > 2.0 * kTwoPi) {
        return PYINS_E_CONFIG_LON;
    }
    if (!std::isfinite(cfg.height_m) || cfg.height_m < -1e4 || cfg.height_m > 1e5) {
        return PYINS_E_CONFIG_HEIGHT;
    }
    if (!finite3(cfg.vel_n_mps) || std::fabs(cfg.vel_n_mps[0]) > 1e4 ||
        std::fabs(cfg.vel_n_mps[1]) > 1e4 || std::fabs(cfg.vel_n_mps[2]) > 1e4) {
        return PYINS_E_CONFIG_VEL;
    }
    if (!finite3(cfg.euler_b_rad) || !std::isfinite(cfg.table_angle_rad)) {
        return PYINS_E_CONFIG_ATT;
    }
    if (cfg.vertical_mode != PYINS_VERTICAL_HOLD && cfg.vertical_mode != PYINS_VERTICAL_FREE) {
        return PYINS_E_CONFIG_MODE;
    }
    if (cfg.coarse_ticks < 0 || cfg.coarse_first_output_ticks < 0 || cfg.coarse_output_every_ticks < 0) {
        return PYINS_E_CONFIG_ALIGN_TICKS;
    }
    if (!(cfg.coarse_ratio > 0.0 && cfg.coarse_ratio < 1.0)) {  // also refuses NaN
        return PYINS_E_CONFIG_ALIGN_RATIO;
    }
    if (cfg.coarse_ticks > 0) {
        const int64_t every = cfg.coarse_output_every_ticks;
        if (cfg.coarse_first_output_ticks > cfg.coarse_ticks) {
            return PYINS_E_CONFIG_ALIGN_TICKS;
        }
        // t_k1 = r t_k2 must be at least one history step in at the first output.
        if (cfg.coarse_ratio * static_cast<double>(cfg.coarse_first_output_ticks) <
            static_cast<double>(every)) {
            return PYINS_E_CONFIG_ALIGN_EARLY;
        }
        if (cfg.coarse_ticks / every > coarse_align::kHistLen - 1) {
            return PYINS_E_CONFIG_ALIGN_LONG;
        }
    }
    return PYINS_OK;
}

void Firmware::init(const pyins_config& raw) {
    const pyins_config cfg = config_resolved(raw);
    cfg_ = cfg;
    dt_ = 1.0 / static_cast<double>(cfg.tick_hz);
    mode_ = Mode::kIdle;
    att_valid_ = cfg.coarse_ticks == 0;
    tick_ = 0;
    table_angle_ = cfg.table_angle_rad;
    encoder_ = wrap_two_pi(cfg.table_angle_rad);
    pmath::sincos(0.5 * encoder_, &enc_sin_half_, &enc_cos_half_);

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
        prm.ratio = cfg.coarse_ratio;
        prm.first_output = cfg.coarse_first_output_ticks;
        prm.output_every = cfg.coarse_output_every_ticks;
        prm.dt = dt_;
        pmath::sincos(cfg.lat_rad, &prm.sin_lat, &prm.cos_lat);
        prm.gravity = earth::normal_gravity(prm.sin_lat, cfg.height_m);
        coarse_align::init(coarse_, prm);
    }
    magic_ = kMagic;
}

void Firmware::end_coarse() {
    // Navigation starts where the alignment ends: the site position, at
    // rest, with the coarse attitude and the increment history (so the
    // coning terms continue without a gap).
    strapdown::NavState nav = sd_.nav;
    nav.vel_n = Vec3::Zero();
    nav.quat_np = attitude::mat_to_quat(coarse_align::mat_n_p(coarse_));
    sd_ = strapdown::make_strapdown(nav, sd_.vertical);
    sd_.hist = coarse_.hist;
    att_valid_ = true;
    mode_ = Mode::kNavigate;
}

int Firmware::step(const pyins_sample& sample, pyins_output* out) {
    if (!finite3(sample.dtheta_p_rad) || !finite3(sample.dv_p_mps) ||
        !std::isfinite(sample.table_angle_rad)) {
        if (out != nullptr) {
            output(out);
        }
        return PYINS_E_SAMPLE_NONFINITE;
    }
    const Vec3 dtheta_p(sample.dtheta_p_rad[0], sample.dtheta_p_rad[1], sample.dtheta_p_rad[2]);
    const Vec3 dv_p(sample.dv_p_mps[0], sample.dv_p_mps[1], sample.dv_p_mps[2]);
    if (mode_ == Mode::kIdle) {
        mode_ = cfg_.coarse_ticks > 0 ? Mode::kCoarseAlign : Mode::kNavigate;
    }
    if (mode_ == Mode::kCoarseAlign) {
        coarse_align::update(coarse_, dtheta_p, dv_p);
        if (coarse_.tick == cfg_.coarse_ticks) {
            end_coarse();
        }
    } else {
        strapdown::update(sd_, dtheta_p, dv_p, dt_);
    }

    // Unwrap the encoder: the table turns far less than pi per tick.
    const double encoder = wrap_two_pi(sample.table_angle_rad);
    table_angle_ = table_angle_ + wrap_pi(encoder - encoder_);
    if (encoder != encoder_) {  // the table moved: refresh the cached half-angle
        encoder_ = encoder;
        pmath::sincos(0.5 * encoder_, &enc_sin_half_, &enc_cos_half_);
    }
    tick_ = tick_ + 1;
    if (out != nullptr) {
        output(out);
    }
    return PYINS_OK;
}

void Firmware::output(pyins_output* out) const {
    const strapdown::NavState& nav = sd_.nav;
    out->tick = tick_;
    out->mode = static_cast<int32_t>(mode_);
    out->fault_flags = 0u;
    out->reserved0 = 0;
    out->lat_rad = nav.lat;
    out->lon_rad = nav.lon;
    out->height_m = nav.height;
    out->vel_n_mps[0] = nav.vel_n(0);
    out->vel_n_mps[1] = nav.vel_n(1);
    out->vel_n_mps[2] = nav.vel_n(2);

    // Ship attitude: C_b^n = C_p^n C_b^p, C_b^p = Rz(-alpha), with alpha the
    // measured (encoder) angle: q_pb = [cos(alpha/2), 0, 0, -sin(alpha/2)].
    const Quat q_pb{enc_cos_half_, 0.0, 0.0, -enc_sin_half_};
    Quat q_np = nav.quat_np;
    bool valid = att_valid_;
    if (mode_ == Mode::kCoarseAlign && coarse_.solved) {
        q_np = attitude::mat_to_quat(coarse_align::mat_n_p(coarse_));
        valid = true;
    }
    out->state_flags = valid ? static_cast<uint32_t>(PYINS_STATE_ATT_VALID) : 0u;
    const Quat q_nb = attitude::quat_normalize(attitude::quat_mul(q_np, q_pb));
    const Vec3 euler_b = attitude::quat_to_euler(q_nb);
    out->quat_nb[0] = q_nb.w;
    out->quat_nb[1] = q_nb.x;
    out->quat_nb[2] = q_nb.y;
    out->quat_nb[3] = q_nb.z;
    out->quat_np[0] = q_np.w;
    out->quat_np[1] = q_np.x;
    out->quat_np[2] = q_np.y;
    out->quat_np[3] = q_np.z;
    out->euler_b_rad[0] = euler_b(0);
    out->euler_b_rad[1] = euler_b(1);
    out->euler_b_rad[2] = euler_b(2);
    out->heading_b_rad = attitude::yaw_to_heading(euler_b(2));
    out->yaw_p_rad = wrap_pi(euler_b(2) + encoder_);
    out->table_angle_rad = table_angle_;
}

}  // namespace pyins::firmware
