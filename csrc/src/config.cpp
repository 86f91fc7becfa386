// config.cpp: see config.hpp. Mirrored by pyins/reference/config.py.
#include "config.hpp"

#include <cmath>

#include "coarse_align.hpp"
#include "indexing.hpp"
#include "types.hpp"

namespace pyins::config {

// --- 2. config_default -----------------------------------------------------

void config_default(pyins_config* cfg) {
    *cfg = pyins_config{};
    cfg->tick_hz = kDefaultTickHz;
    cfg->vertical_mode = PYINS_VERTICAL_HOLD;
}


// --- 3. config_resolved: 0 -> the default ----------------------------------

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
    if (cfg.fine_states == 0) {
        cfg.fine_states = kDefaultFineStates;
    }
    if (cfg.fine_meas_every_ticks == 0) {
        cfg.fine_meas_every_ticks = cfg.fine_states == 12 ? kDefaultMovingMeasEverySecond * cfg.tick_hz
                                                          : kDefaultFineMeasEvery;
    }
    if (cfg.fine_pos_sigma_m == 0.0) {
        cfg.fine_pos_sigma_m = kDefaultPosSigma;
    }
    if (cfg.fine_sigma0_vel_mps == 0.0) {
        cfg.fine_sigma0_vel_mps = kDefaultSigma0Vel;
    }
    if (cfg.fine_gyro_arw == 0.0) {
        cfg.fine_gyro_arw = kDefaultFineArw;
    }
    if (cfg.fine_accel_vrw == 0.0) {
        cfg.fine_accel_vrw = kDefaultFineVrw;
    }
    for (int i = 0; i < 3; ++i) {
        if (cfg.fine_sigma0_att_rad[i] == 0.0) {
            cfg.fine_sigma0_att_rad[i] = cfg.fine_states == 12 ? kDefaultMovingSigmaAtt[i]
                                                               : kDefaultFineSigmaAtt[i];
        }
    }
    if (cfg.fine_sigma0_gyro == 0.0) {
        cfg.fine_sigma0_gyro = kDefaultFineSigmaGyro;
    }
    if (cfg.fine_sigma0_accel == 0.0) {
        cfg.fine_sigma0_accel = kDefaultFineSigmaAccel;
    }
    if (cfg.index_scheme != PYINS_INDEX_CUSTOM) {
        if (cfg.index_stop_ticks == 0) {
            const int32_t s = cfg.index_scheme == PYINS_INDEX_SINGLE_FWD_REV ? kDefaultStopSeed003S
                                                                            : kDefaultStopS;
            cfg.index_stop_ticks = s * cfg.tick_hz;
        }
        if (cfg.index_rate_rad_s == 0.0) {
            cfg.index_rate_rad_s = kDefaultIndexRate;
        }
        if (cfg.index_accel_rad_s2 == 0.0) {
            cfg.index_accel_rad_s2 = kDefaultIndexAccel;
        }
        if (cfg.index_delta == 0.0) {
            cfg.index_delta = kDefaultIndexDelta;
        }
    }
    if (cfg.index_max_flex_rad == 0.0) {
        cfg.index_max_flex_rad = kDefaultIndexMaxFlex;
    }
    if (cfg.index_tolerance_rad == 0.0) {
        cfg.index_tolerance_rad = kDefaultIndexTolerance;
    }
    if (cfg.index_jump_rad == 0.0) {
        cfg.index_jump_rad = kDefaultIndexJump;
    }
    if (cfg.index_timeout_ticks == 0) {
        cfg.index_timeout_ticks = kDefaultIndexTimeoutS * cfg.tick_hz;
    }
    if (cfg.seq_max_gap_ticks == 0) {
        cfg.seq_max_gap_ticks = kDefaultSeqMaxGap;
    }
    if (cfg.sat_gyro_rad == 0.0) {
        cfg.sat_gyro_rad = kDefaultSatGyroRate / static_cast<double>(cfg.tick_hz);
    }
    if (cfg.sat_accel_mps == 0.0) {
        cfg.sat_accel_mps = kDefaultSatAccel / static_cast<double>(cfg.tick_hz);
    }
    if (cfg.integrity_nis_window == 0) {
        cfg.integrity_nis_window = kDefaultNisWindow;
    }
    if (cfg.integrity_nis_max == 0.0) {
        cfg.integrity_nis_max = kDefaultNisMax;
    }
    if (cfg.integrity_coarse_rad == 0.0) {
        cfg.integrity_coarse_rad = kDefaultCoarseWander;
    }
    if (cfg.nav_every_ticks == 0) {
        cfg.nav_every_ticks = kDefaultNavEveryS * cfg.tick_hz;
    }
    if (cfg.nav_gate == 0.0) {
        cfg.nav_gate = kDefaultNavGate;
    }
    if (cfg.nav_reject_limit == 0) {
        cfg.nav_reject_limit = kDefaultNavRejectLimit;
    }
    if (cfg.ref_max_latency_ticks == 0) {
        cfg.ref_max_latency_ticks = kDefaultRefLatencyS * cfg.tick_hz;
    }
    return cfg;
}

// --- 4. config_check: the first status that applies ----------------------

namespace {

/// The indexing part of config_check, on a resolved configuration.
int index_check(const pyins_config& cfg) {
    if (cfg.index_scheme < PYINS_INDEX_NONE || cfg.index_scheme > PYINS_INDEX_HEADING_ISOLATION) {
        return PYINS_E_CONFIG_INDEX_SCHEME;
    }
    if (cfg.index_scheme == PYINS_INDEX_NONE) {
        return PYINS_OK;
    }
    bool flexible = cfg.index_scheme == PYINS_INDEX_FLEXIBLE_TWO ||
                    cfg.index_scheme == PYINS_INDEX_FLEXIBLE_DERIVED;
    if (cfg.index_scheme == PYINS_INDEX_CUSTOM) {
        if (cfg.index_n_steps < 1 || cfg.index_n_steps > indexing::kMaxSteps) {
            return PYINS_E_CONFIG_INDEX_EMPTY;
        }
        for (int32_t i = 0; i < cfg.index_n_steps; ++i) {
            const pyins_index_step& s = cfg.index_steps[i];
            if (s.stop_ticks < 1 || !std::isfinite(s.angle_rad) ||
                (s.kind != PYINS_INDEX_FIXED && s.kind != PYINS_INDEX_FLEX_COS &&
                 s.kind != PYINS_INDEX_FLEX_SIN) ||
                (s.kind == PYINS_INDEX_FIXED && s.angle_rad == 0.0) ||
                std::fabs(s.angle_rad) > 16.0 * kPi) {
                return PYINS_E_CONFIG_INDEX_STEP;
            }
            flexible = flexible || s.kind != PYINS_INDEX_FIXED;
        }
    } else if (cfg.index_stop_ticks < 1) {
        return PYINS_E_CONFIG_INDEX_STEP;
    }
    if (!(cfg.index_rate_rad_s > 0.0) || !(cfg.index_accel_rad_s2 > 0.0) ||
        !std::isfinite(cfg.index_rate_rad_s) || !std::isfinite(cfg.index_accel_rad_s2)) {
        return PYINS_E_CONFIG_INDEX_RATE;
    }
    if (flexible && (!(cfg.index_delta > 0.0) || !(cfg.index_delta < 1.0))) {
        return PYINS_E_CONFIG_INDEX_DELTA;
    }
    if (!(cfg.index_max_flex_rad > 0.0) || !(cfg.index_tolerance_rad > 0.0) ||
        !(cfg.index_jump_rad > 0.0) || !std::isfinite(cfg.index_max_flex_rad) ||
        !std::isfinite(cfg.index_tolerance_rad) || !std::isfinite(cfg.index_jump_rad) ||
        cfg.index_timeout_ticks < 1) {
        return PYINS_E_CONFIG_INDEX_STEP;
    }
    return PYINS_OK;
}

}  // namespace

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
    // the DVL's mounting: any rotation, its vector at most pi long (a longer
    // one is a shorter one's rotation: degrees written as radians)
    const double* m = cfg.dvl_align_rad;
    if (!finite3(cfg.euler_b_rad) || !std::isfinite(cfg.table_angle_rad) || !finite3(m) ||
        !(m[0] * m[0] + m[1] * m[1] + m[2] * m[2] <= kPi * kPi)) {
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
        if (cfg.coarse_method != PYINS_COARSE_FIT && cfg.coarse_method != PYINS_COARSE_FIT_VEL &&
            cfg.coarse_ticks / every > coarse_align::kHistLen - 1) {
            return PYINS_E_CONFIG_ALIGN_LONG;
        }
    }
    if (cfg.fine_ticks < 0) {
        return PYINS_E_CONFIG_ALIGN_TICKS;
    }
    if ((cfg.fine_states != 5 && cfg.fine_states != 8 && cfg.fine_states != 12) ||
        cfg.fine_meas_every_ticks < 0 ||
        (cfg.fine_correction != PYINS_FINE_FEEDBACK && cfg.fine_correction != PYINS_FINE_OPEN_LOOP) ||
        (cfg.fine_noise != PYINS_FINE_NOISE_MEASURED && cfg.fine_noise != PYINS_FINE_NOISE_CONFIGURED)) {
        return PYINS_E_CONFIG_FINE;
    }
    const double noise[9] = {cfg.fine_gyro_arw, cfg.fine_accel_vrw, cfg.fine_sigma0_att_rad[0],
                             cfg.fine_sigma0_att_rad[1], cfg.fine_sigma0_att_rad[2],
                             cfg.fine_sigma0_gyro, cfg.fine_sigma0_accel, cfg.fine_pos_sigma_m,
                             cfg.fine_sigma0_vel_mps};
    for (double v : noise) {
        if (!(v > 0.0) || !std::isfinite(v)) {
            return PYINS_E_CONFIG_NOISE;
        }
    }
    // the site's slow motion: 0 (a rigid site) or a finite density
    if (!(cfg.fine_site_accel >= 0.0) || !std::isfinite(cfg.fine_site_accel)) {
        return PYINS_E_CONFIG_NOISE;
    }
    const int index_status = index_check(cfg);
    if (index_status != PYINS_OK) {
        return index_status;
    }
    if (cfg.index_sums != PYINS_INDEX_SUMS_STOPS && cfg.index_sums != PYINS_INDEX_SUMS_ALL) {
        return PYINS_E_CONFIG_INDEX_SUMS;
    }
    if ((cfg.seq_mode != PYINS_SEQ_OFF && cfg.seq_mode != PYINS_SEQ_CHECK) ||
        cfg.seq_max_gap_ticks < 1 || cfg.seq_max_gap_ticks > kMaxSeqGap) {
        return PYINS_E_CONFIG_SEQ;
    }
    if (!(cfg.sat_gyro_rad > 0.0) || !std::isfinite(cfg.sat_gyro_rad) ||
        !(cfg.sat_accel_mps > 0.0) || !std::isfinite(cfg.sat_accel_mps)) {
        return PYINS_E_CONFIG_SATURATION;
    }
    const double* levers[4] = {cfg.lever_b_m, cfg.lever_p_m, cfg.dvl_lever_b_m, cfg.gnss_lever_b_m};
    for (const double* r : levers) {
        if (!finite3(r) || r[0] * r[0] + r[1] * r[1] + r[2] * r[2] > kMaxLeverM * kMaxLeverM) {
            return PYINS_E_CONFIG_LEVER;
        }
    }
    if (cfg.coarse_method != PYINS_COARSE_TRIAD && cfg.coarse_method != PYINS_COARSE_FIT &&
        cfg.coarse_method != PYINS_COARSE_EQ8 && cfg.coarse_method != PYINS_COARSE_FIT_VEL) {
        return PYINS_E_CONFIG_COARSE_METHOD;
    }
    // under way the static fine filters cannot follow: the navigation filter aligns finely
    if (cfg.coarse_method == PYINS_COARSE_FIT_VEL && cfg.coarse_ticks > 0 &&
        (cfg.fine_ticks > 0 || cfg.nav_mode == PYINS_NAV_UNDAMPED)) {
        return PYINS_E_CONFIG_COARSE_METHOD;
    }
    if ((cfg.coarse_method == PYINS_COARSE_FIT || cfg.coarse_method == PYINS_COARSE_FIT_VEL) &&
        cfg.coarse_ticks > 0 &&
        cfg.coarse_first_output_ticks / cfg.coarse_output_every_ticks < coarse_align::kFitMinIntervals) {
        return PYINS_E_CONFIG_ALIGN_EARLY;
    }
    if (cfg.integrity_nis_window < -1 || !(cfg.integrity_nis_max > 0.0) ||
        !std::isfinite(cfg.integrity_nis_max) || !(cfg.integrity_coarse_rad > 0.0) ||
        !std::isfinite(cfg.integrity_coarse_rad)) {
        return PYINS_E_CONFIG_INTEGRITY;
    }
    if ((cfg.nav_mode != PYINS_NAV_AUTO && cfg.nav_mode != PYINS_NAV_UNDAMPED &&
         cfg.nav_mode != PYINS_NAV_DAMPED && cfg.nav_mode != PYINS_NAV_INTEGRATED) ||
        cfg.nav_every_ticks < 1 || cfg.nav_every_ticks > kMaxNavEveryS * cfg.tick_hz ||
        !(cfg.nav_gate > 0.0) || !std::isfinite(cfg.nav_gate) || cfg.nav_reject_limit < 1 ||
        cfg.ref_max_latency_ticks < 1 || cfg.ref_max_latency_ticks > kRefHorizonS * cfg.tick_hz) {
        return PYINS_E_CONFIG_NAV;
    }
    // the filter's model beyond its bias states: 0 (not modelled) or a
    // finite value within the bound (pyins_core.h)
    const double model[5] = {cfg.nav_gyro_bias_rw, cfg.nav_table_scale_sigma, cfg.nav_table_mis_sigma,
                             cfg.nav_level_scale_sigma, cfg.nav_level_mis_sigma};
    const double bound[5] = {kMaxNavGyroBiasRw, kMaxNavTableSigma, kMaxNavTableSigma, kMaxNavTableSigma,
                             kMaxNavTableSigma};
    for (int i = 0; i < 5; ++i) {
        if (!(model[i] >= 0.0) || !(model[i] <= bound[i])) {
            return PYINS_E_CONFIG_NAV;
        }
    }
    return PYINS_OK;
}

}  // namespace pyins::config
