"""The configuration contract: the defaults, their resolution, the checks.

Mirrors ``csrc/src/config.{hpp,cpp}``: every configuration field of
``pyins_config`` with 0 meaning "the default" (``config_default`` is the
zeroed struct), ``config_resolved`` putting the defaults in, and
``config_check`` returning ``PYINS_OK`` or the first ``PYINS_E_CONFIG_*``
that applies (``index_check`` is its indexing part). The firmware instance
(``firmware.py``) takes a checked configuration and resolves it.
"""
import math

import numpy as np

from pyins.units import ARCMIN_TO_RAD, DEG_TO_RAD, G0, TICK_HZ, TWO_PI

from . import abi, coarse_align, indexing

# --- 1. the defaults, one table (config.hpp: kDefault*) ---------------------
DEFAULT_TICK_HZ = TICK_HZ               #: kDefaultTickHz
DEFAULT_COARSE_FIRST_S = 20             #: kDefaultCoarseFirstS (seed 000: first output 20 s)
DEFAULT_COARSE_EVERY_S = 1              #: kDefaultCoarseEveryS (then every 1 s)
DEFAULT_COARSE_RATIO = 0.5              #: kDefaultCoarseRatio
DEFAULT_FINE_STATES = 5                 #: kDefaultFineStates
DEFAULT_FINE_MEAS_EVERY = 10            #: kDefaultFineMeasEvery (10 Hz updates at 100 Hz)
DEFAULT_MOVING_MEAS_EVERY_SECOND = 1    #: kDefaultMovingMeasEverySecond (1 Hz position updates)
DEFAULT_POS_SIGMA = 0.5                 #: kDefaultPosSigma [m]
DEFAULT_SIGMA0_VEL = 0.5                #: kDefaultSigma0Vel [m/s]
DEFAULT_FINE_ARW = 0.001 * DEG_TO_RAD / 60.0      #: kDefaultFineArw: 0.001 deg/sqrt(h)
DEFAULT_FINE_VRW = 10.0e-6 * G0                   #: kDefaultFineVrw: 10 ug/sqrt(Hz)
DEFAULT_FINE_SIGMA_ATT = (100.0 * ARCMIN_TO_RAD, 100.0 * ARCMIN_TO_RAD,
                          600.0 * ARCMIN_TO_RAD)  #: kDefaultFineSigmaAtt: 10 x [10', 10', 60']
DEFAULT_MOVING_SIGMA_ATT = (1.0 * ARCMIN_TO_RAD, 1.0 * ARCMIN_TO_RAD,
                            10.0 * ARCMIN_TO_RAD)  #: kDefaultMovingSigmaAtt: 1', 1', 10'
DEFAULT_FINE_SIGMA_GYRO = 0.01 * DEG_TO_RAD / 3600.0   #: kDefaultFineSigmaGyro: 0.01 deg/h
DEFAULT_FINE_SIGMA_ACCEL = 100.0e-6 * G0               #: kDefaultFineSigmaAccel: 100 ug
DEFAULT_INDEX_RATE = 6.0 * DEG_TO_RAD        #: kDefaultIndexRate (seeds 002, 003: 6 deg/s)
DEFAULT_INDEX_ACCEL = 30.0 * DEG_TO_RAD      #: kDefaultIndexAccel
DEFAULT_INDEX_DELTA = 0.01                   #: kDefaultIndexDelta (seed 002, at 100 Hz)
DEFAULT_INDEX_MAX_FLEX = 720.0 * DEG_TO_RAD  #: kDefaultIndexMaxFlex
DEFAULT_INDEX_TOLERANCE = 0.5 * DEG_TO_RAD   #: kDefaultIndexTolerance
DEFAULT_INDEX_JUMP = 5.0 * DEG_TO_RAD        #: kDefaultIndexJump
DEFAULT_INDEX_TIMEOUT_S = 2                  #: kDefaultIndexTimeoutS
DEFAULT_STOP_SEED003_S = 60                  #: kDefaultStopSeed003S
DEFAULT_STOP_S = 300                         #: kDefaultStopS
DEFAULT_SAT_GYRO_RATE = 400.0 * DEG_TO_RAD   #: kDefaultSatGyroRate [rad/s]
DEFAULT_SAT_ACCEL = 20.0 * G0                #: kDefaultSatAccel [m/s^2]
DEFAULT_SEQ_MAX_GAP = 2                      #: kDefaultSeqMaxGap [ticks]
DEFAULT_NIS_WINDOW = 100                     #: kDefaultNisWindow
DEFAULT_NIS_MAX = 4.0                        #: kDefaultNisMax
DEFAULT_COARSE_WANDER = 30.0 * ARCMIN_TO_RAD  #: kDefaultCoarseWander
DEFAULT_NAV_EVERY_S = 1                      #: kDefaultNavEveryS
MAX_NAV_EVERY_S = 10                         #: kMaxNavEveryS
DEFAULT_NAV_GATE = 13.8155                   #: kDefaultNavGate: -2 ln(0.001)
DEFAULT_NAV_REJECT_LIMIT = 10                #: kDefaultNavRejectLimit
DEFAULT_REF_LATENCY_S = 1                    #: kDefaultRefLatencyS
REF_HORIZON_S = 10                           #: kRefHorizonS
MAX_NAV_GYRO_BIAS_RW = 1e-6                  #: kMaxNavGyroBiasRw [rad/s/sqrt(s)]
MAX_NAV_TABLE_SIGMA = 0.01                   #: kMaxNavTableSigma
ALIGN_MAX_SPEED = 0.5                        #: kAlignMaxSpeed [m/s]
COARSE_REF_GAP_S = 3                         #: kCoarseRefGapS: the longest gap in an alignment under way [s]
NAV_SIGMA0_POS = 10.0                        #: kNavSigma0Pos [m]
NAV_SIGMA0_VEL = 0.1                         #: kNavSigma0Vel [m/s]

# --- the limits the checks hold a configuration to ---------------------------
MAX_TICK_HZ = 10000                 #: kMaxTickHz
MAX_LAT_RAD = 89.9 * np.pi / 180.0  #: kMaxLatRad: the ENU frame is singular at the poles
MAX_SEQ_GAP = 100                   #: kMaxSeqGap [ticks]
MAX_LEVER_M = 100.0                 #: kMaxLeverM


# --- 2. config_default -------------------------------------------------------
def config_default():
    """Default configuration as a dict (equal to a zeroed C struct)."""
    return {
        "tick_hz": DEFAULT_TICK_HZ,
        "vertical_mode": abi.PYINS_VERTICAL_HOLD,
        "lat_rad": 0.0,
        "lon_rad": 0.0,
        "height_m": 0.0,
        "vel_n_mps": np.zeros(3),
        "euler_b_rad": np.zeros(3),
        "table_angle_rad": 0.0,
        "coarse_ticks": 0,
        "coarse_first_output_ticks": 0,
        "coarse_output_every_ticks": 0,
        "reserved0": 0,
        "coarse_ratio": 0.0,
        "fine_ticks": 0,
        "fine_states": 0,
        "fine_meas_every_ticks": 0,
        "fine_correction": abi.PYINS_FINE_FEEDBACK,
        "fine_gyro_arw": 0.0,
        "fine_accel_vrw": 0.0,
        "fine_sigma0_att_rad": np.zeros(3),
        "fine_sigma0_gyro": 0.0,
        "fine_sigma0_accel": 0.0,
        "index_scheme": abi.PYINS_INDEX_NONE,
        "index_stop_ticks": 0,
        "index_timeout_ticks": 0,
        "index_n_steps": 0,
        "index_rate_rad_s": 0.0,
        "index_accel_rad_s2": 0.0,
        "index_delta": 0.0,
        "index_max_flex_rad": 0.0,
        "index_tolerance_rad": 0.0,
        "index_jump_rad": 0.0,
        "index_steps": [],    # list of (stop_ticks, kind, angle_rad)
        "seq_mode": abi.PYINS_SEQ_OFF,
        "seq_max_gap_ticks": 0,
        "sat_gyro_rad": 0.0,
        "sat_accel_mps": 0.0,
        "index_sums": abi.PYINS_INDEX_SUMS_STOPS,
        "reserved1": 0,
        "lever_b_m": np.zeros(3),
        "lever_p_m": np.zeros(3),
        "coarse_method": abi.PYINS_COARSE_TRIAD,
        "reserved2": 0,
        "integrity_nis_window": 0,
        "fine_noise": abi.PYINS_FINE_NOISE_MEASURED,
        "integrity_nis_max": 0.0,
        "integrity_coarse_rad": 0.0,
        "fine_pos_sigma_m": 0.0,
        "fine_sigma0_vel_mps": 0.0,
        "fine_site_accel": 0.0,
        "nav_mode": abi.PYINS_NAV_AUTO,
        "nav_every_ticks": 0,
        "nav_gate": 0.0,
        "nav_reject_limit": 0,
        "ref_max_latency_ticks": 0,
        "dvl_align_rad": np.zeros(3),
        "dvl_lever_b_m": np.zeros(3),
        "gnss_lever_b_m": np.zeros(3),
        "nav_gyro_bias_rw": 0.0,
        "nav_table_scale_sigma": 0.0,
        "nav_table_mis_sigma": 0.0,
        "nav_level_scale_sigma": 0.0,
        "nav_level_mis_sigma": 0.0,
    }


# --- 3. config_resolved: 0 -> the default ---------------------------------
def config_resolved(cfg):
    """The configuration with the zero-means-default fields resolved."""
    cfg = dict(cfg)
    if cfg["tick_hz"] == 0:
        cfg["tick_hz"] = DEFAULT_TICK_HZ
    if cfg["coarse_first_output_ticks"] == 0:
        cfg["coarse_first_output_ticks"] = DEFAULT_COARSE_FIRST_S * cfg["tick_hz"]
    if cfg["coarse_output_every_ticks"] == 0:
        cfg["coarse_output_every_ticks"] = DEFAULT_COARSE_EVERY_S * cfg["tick_hz"]
    if cfg["coarse_ratio"] == 0.0:
        cfg["coarse_ratio"] = DEFAULT_COARSE_RATIO
    if cfg["fine_states"] == 0:
        cfg["fine_states"] = DEFAULT_FINE_STATES
    if cfg["fine_meas_every_ticks"] == 0:
        cfg["fine_meas_every_ticks"] = (DEFAULT_MOVING_MEAS_EVERY_SECOND * cfg["tick_hz"]
                                        if cfg["fine_states"] == 12 else DEFAULT_FINE_MEAS_EVERY)
    if cfg["fine_pos_sigma_m"] == 0.0:
        cfg["fine_pos_sigma_m"] = DEFAULT_POS_SIGMA
    if cfg["fine_sigma0_vel_mps"] == 0.0:
        cfg["fine_sigma0_vel_mps"] = DEFAULT_SIGMA0_VEL
    if cfg["fine_gyro_arw"] == 0.0:
        cfg["fine_gyro_arw"] = DEFAULT_FINE_ARW
    if cfg["fine_accel_vrw"] == 0.0:
        cfg["fine_accel_vrw"] = DEFAULT_FINE_VRW
    sig = np.array(cfg["fine_sigma0_att_rad"], dtype=float)
    for i in range(3):
        if sig[i] == 0.0:
            sig[i] = DEFAULT_MOVING_SIGMA_ATT[i] if cfg["fine_states"] == 12 else DEFAULT_FINE_SIGMA_ATT[i]
    cfg["fine_sigma0_att_rad"] = sig
    if cfg["fine_sigma0_gyro"] == 0.0:
        cfg["fine_sigma0_gyro"] = DEFAULT_FINE_SIGMA_GYRO
    if cfg["fine_sigma0_accel"] == 0.0:
        cfg["fine_sigma0_accel"] = DEFAULT_FINE_SIGMA_ACCEL
    if cfg["index_scheme"] != abi.PYINS_INDEX_CUSTOM:
        if cfg["index_stop_ticks"] == 0:
            s = (DEFAULT_STOP_SEED003_S if cfg["index_scheme"] == abi.PYINS_INDEX_SINGLE_FWD_REV
                 else DEFAULT_STOP_S)
            cfg["index_stop_ticks"] = s * cfg["tick_hz"]
        if cfg["index_rate_rad_s"] == 0.0:
            cfg["index_rate_rad_s"] = DEFAULT_INDEX_RATE
        if cfg["index_accel_rad_s2"] == 0.0:
            cfg["index_accel_rad_s2"] = DEFAULT_INDEX_ACCEL
        if cfg["index_delta"] == 0.0:
            cfg["index_delta"] = DEFAULT_INDEX_DELTA
    if cfg["index_max_flex_rad"] == 0.0:
        cfg["index_max_flex_rad"] = DEFAULT_INDEX_MAX_FLEX
    if cfg["index_tolerance_rad"] == 0.0:
        cfg["index_tolerance_rad"] = DEFAULT_INDEX_TOLERANCE
    if cfg["index_jump_rad"] == 0.0:
        cfg["index_jump_rad"] = DEFAULT_INDEX_JUMP
    if cfg["index_timeout_ticks"] == 0:
        cfg["index_timeout_ticks"] = DEFAULT_INDEX_TIMEOUT_S * cfg["tick_hz"]
    if cfg["seq_max_gap_ticks"] == 0:
        cfg["seq_max_gap_ticks"] = DEFAULT_SEQ_MAX_GAP
    if cfg["sat_gyro_rad"] == 0.0:
        cfg["sat_gyro_rad"] = DEFAULT_SAT_GYRO_RATE / float(cfg["tick_hz"])
    if cfg["sat_accel_mps"] == 0.0:
        cfg["sat_accel_mps"] = DEFAULT_SAT_ACCEL / float(cfg["tick_hz"])
    if cfg["integrity_nis_window"] == 0:
        cfg["integrity_nis_window"] = DEFAULT_NIS_WINDOW
    if cfg["integrity_nis_max"] == 0.0:
        cfg["integrity_nis_max"] = DEFAULT_NIS_MAX
    if cfg["integrity_coarse_rad"] == 0.0:
        cfg["integrity_coarse_rad"] = DEFAULT_COARSE_WANDER
    if cfg["nav_every_ticks"] == 0:
        cfg["nav_every_ticks"] = DEFAULT_NAV_EVERY_S * cfg["tick_hz"]
    if cfg["nav_gate"] == 0.0:
        cfg["nav_gate"] = DEFAULT_NAV_GATE
    if cfg["nav_reject_limit"] == 0:
        cfg["nav_reject_limit"] = DEFAULT_NAV_REJECT_LIMIT
    if cfg["ref_max_latency_ticks"] == 0:
        cfg["ref_max_latency_ticks"] = DEFAULT_REF_LATENCY_S * cfg["tick_hz"]
    return cfg


# --- 4. config_check: the first status that applies -----------------------
def index_check(cfg):
    """The indexing part of config_check (mirrors index_check)."""
    scheme = cfg["index_scheme"]
    if scheme < abi.PYINS_INDEX_NONE or scheme > abi.PYINS_INDEX_HEADING_ISOLATION:
        return abi.PYINS_E_CONFIG_INDEX_SCHEME
    if scheme == abi.PYINS_INDEX_NONE:
        return abi.PYINS_OK
    flexible = scheme in (abi.PYINS_INDEX_FLEXIBLE_TWO, abi.PYINS_INDEX_FLEXIBLE_DERIVED)
    if scheme == abi.PYINS_INDEX_CUSTOM:
        n = cfg["index_n_steps"]
        if n < 1 or n > indexing.MAX_STEPS:
            return abi.PYINS_E_CONFIG_INDEX_EMPTY
        for stop, kind, angle in list(cfg["index_steps"])[:n]:
            if (stop < 1 or not math.isfinite(angle) or kind not in (1, 2, 3)
                    or (kind == abi.PYINS_INDEX_FIXED and angle == 0.0) or abs(angle) > 16.0 * np.pi):
                return abi.PYINS_E_CONFIG_INDEX_STEP
            flexible = flexible or kind != abi.PYINS_INDEX_FIXED
    elif cfg["index_stop_ticks"] < 1:
        return abi.PYINS_E_CONFIG_INDEX_STEP
    rate, accel = cfg["index_rate_rad_s"], cfg["index_accel_rad_s2"]
    if not (rate > 0.0) or not (accel > 0.0) or not math.isfinite(rate) or not math.isfinite(accel):
        return abi.PYINS_E_CONFIG_INDEX_RATE
    if flexible and not (0.0 < cfg["index_delta"] < 1.0):
        return abi.PYINS_E_CONFIG_INDEX_DELTA
    vals = [cfg["index_max_flex_rad"], cfg["index_tolerance_rad"], cfg["index_jump_rad"]]
    if any(not (v > 0.0) or not math.isfinite(v) for v in vals) or cfg["index_timeout_ticks"] < 1:
        return abi.PYINS_E_CONFIG_INDEX_STEP
    return abi.PYINS_OK


def finite3(v):
    """All three components finite (mirrors types.hpp's finite3)."""
    return all(math.isfinite(x) for x in v)


def config_check(raw):
    """PYINS_OK or the first PYINS_E_CONFIG_* that applies (mirrors config_check)."""
    if raw["tick_hz"] < 0 or raw["tick_hz"] > MAX_TICK_HZ:
        return abi.PYINS_E_CONFIG_RATE
    cfg = config_resolved(raw)
    if not math.isfinite(cfg["lat_rad"]) or abs(cfg["lat_rad"]) > MAX_LAT_RAD:
        return abi.PYINS_E_CONFIG_LAT
    if not math.isfinite(cfg["lon_rad"]) or abs(cfg["lon_rad"]) > 2.0 * TWO_PI:
        return abi.PYINS_E_CONFIG_LON
    h = cfg["height_m"]
    if not math.isfinite(h) or h < -1e4 or h > 1e5:
        return abi.PYINS_E_CONFIG_HEIGHT
    v = cfg["vel_n_mps"]
    if not finite3(v) or abs(v[0]) > 1e4 or abs(v[1]) > 1e4 or abs(v[2]) > 1e4:
        return abi.PYINS_E_CONFIG_VEL
    m = cfg["dvl_align_rad"]
    if (not finite3(cfg["euler_b_rad"]) or not math.isfinite(cfg["table_angle_rad"]) or not finite3(m)
            or not m[0] * m[0] + m[1] * m[1] + m[2] * m[2] <= np.pi * np.pi):
        return abi.PYINS_E_CONFIG_ATT
    if cfg["vertical_mode"] not in (abi.PYINS_VERTICAL_HOLD, abi.PYINS_VERTICAL_FREE):
        return abi.PYINS_E_CONFIG_MODE
    if cfg["coarse_ticks"] < 0 or cfg["coarse_first_output_ticks"] < 0 or cfg["coarse_output_every_ticks"] < 0:
        return abi.PYINS_E_CONFIG_ALIGN_TICKS
    if not (0.0 < cfg["coarse_ratio"] < 1.0):
        return abi.PYINS_E_CONFIG_ALIGN_RATIO
    if cfg["coarse_ticks"] > 0:
        every = cfg["coarse_output_every_ticks"]
        if cfg["coarse_first_output_ticks"] > cfg["coarse_ticks"]:
            return abi.PYINS_E_CONFIG_ALIGN_TICKS
        if cfg["coarse_ratio"] * float(cfg["coarse_first_output_ticks"]) < float(every):
            return abi.PYINS_E_CONFIG_ALIGN_EARLY
        if (cfg["coarse_method"] not in (abi.PYINS_COARSE_FIT, abi.PYINS_COARSE_FIT_VEL)
                and cfg["coarse_ticks"] // every > coarse_align.HIST_LEN - 1):
            return abi.PYINS_E_CONFIG_ALIGN_LONG
    if cfg["fine_ticks"] < 0:
        return abi.PYINS_E_CONFIG_ALIGN_TICKS
    if (cfg["fine_states"] not in (5, 8, 12) or cfg["fine_meas_every_ticks"] < 0
            or cfg["fine_correction"] not in (abi.PYINS_FINE_FEEDBACK, abi.PYINS_FINE_OPEN_LOOP)
            or cfg["fine_noise"] not in (abi.PYINS_FINE_NOISE_MEASURED, abi.PYINS_FINE_NOISE_CONFIGURED)):
        return abi.PYINS_E_CONFIG_FINE
    noise = [cfg["fine_gyro_arw"], cfg["fine_accel_vrw"], *cfg["fine_sigma0_att_rad"],
             cfg["fine_sigma0_gyro"], cfg["fine_sigma0_accel"], cfg["fine_pos_sigma_m"],
             cfg["fine_sigma0_vel_mps"]]
    for v in noise:
        if not (v > 0.0) or not math.isfinite(v):
            return abi.PYINS_E_CONFIG_NOISE
    # the site's slow motion: 0 (a rigid site) or a finite density
    if not (cfg["fine_site_accel"] >= 0.0) or not math.isfinite(cfg["fine_site_accel"]):
        return abi.PYINS_E_CONFIG_NOISE
    index_status = index_check(cfg)
    if index_status != abi.PYINS_OK:
        return index_status
    if cfg["index_sums"] not in (abi.PYINS_INDEX_SUMS_STOPS, abi.PYINS_INDEX_SUMS_ALL):
        return abi.PYINS_E_CONFIG_INDEX_SUMS
    if (cfg["seq_mode"] not in (abi.PYINS_SEQ_OFF, abi.PYINS_SEQ_CHECK)
            or not 1 <= cfg["seq_max_gap_ticks"] <= MAX_SEQ_GAP):
        return abi.PYINS_E_CONFIG_SEQ
    sat = (cfg["sat_gyro_rad"], cfg["sat_accel_mps"])
    if any(not (v > 0.0) or not math.isfinite(v) for v in sat):
        return abi.PYINS_E_CONFIG_SATURATION
    for r in (cfg["lever_b_m"], cfg["lever_p_m"], cfg["dvl_lever_b_m"], cfg["gnss_lever_b_m"]):
        if not finite3(r) or r[0] * r[0] + r[1] * r[1] + r[2] * r[2] > MAX_LEVER_M * MAX_LEVER_M:
            return abi.PYINS_E_CONFIG_LEVER
    if cfg["coarse_method"] not in (abi.PYINS_COARSE_TRIAD, abi.PYINS_COARSE_FIT, abi.PYINS_COARSE_EQ8,
                                    abi.PYINS_COARSE_FIT_VEL):
        return abi.PYINS_E_CONFIG_COARSE_METHOD
    # under way the static fine filters cannot follow: the navigation filter aligns finely
    if (cfg["coarse_method"] == abi.PYINS_COARSE_FIT_VEL and cfg["coarse_ticks"] > 0
            and (cfg["fine_ticks"] > 0 or cfg["nav_mode"] == abi.PYINS_NAV_UNDAMPED)):
        return abi.PYINS_E_CONFIG_COARSE_METHOD
    if (cfg["coarse_method"] in (abi.PYINS_COARSE_FIT, abi.PYINS_COARSE_FIT_VEL) and cfg["coarse_ticks"] > 0
            and cfg["coarse_first_output_ticks"] // cfg["coarse_output_every_ticks"]
            < coarse_align.FIT_MIN_INTERVALS):
        return abi.PYINS_E_CONFIG_ALIGN_EARLY
    nis_max, wander = cfg["integrity_nis_max"], cfg["integrity_coarse_rad"]
    if (cfg["integrity_nis_window"] < -1 or not (nis_max > 0.0) or not math.isfinite(nis_max)
            or not (wander > 0.0) or not math.isfinite(wander)):
        return abi.PYINS_E_CONFIG_INTEGRITY
    hz = cfg["tick_hz"]
    if (cfg["nav_mode"] not in (abi.PYINS_NAV_AUTO, abi.PYINS_NAV_UNDAMPED, abi.PYINS_NAV_DAMPED,
                               abi.PYINS_NAV_INTEGRATED)
            or not 1 <= cfg["nav_every_ticks"] <= MAX_NAV_EVERY_S * hz
            or not (cfg["nav_gate"] > 0.0) or not math.isfinite(cfg["nav_gate"])
            or cfg["nav_reject_limit"] < 1
            or not 1 <= cfg["ref_max_latency_ticks"] <= REF_HORIZON_S * hz):
        return abi.PYINS_E_CONFIG_NAV
    # the filter's model beyond its bias states: 0 (not modelled) or a
    # finite value within the bound (pyins_core.h)
    model = (cfg["nav_gyro_bias_rw"], cfg["nav_table_scale_sigma"], cfg["nav_table_mis_sigma"],
             cfg["nav_level_scale_sigma"], cfg["nav_level_mis_sigma"])
    bound = (MAX_NAV_GYRO_BIAS_RW, MAX_NAV_TABLE_SIGMA, MAX_NAV_TABLE_SIGMA, MAX_NAV_TABLE_SIGMA,
             MAX_NAV_TABLE_SIGMA)
    for i in range(5):
        if not (model[i] >= 0.0) or not (model[i] <= bound[i]):
            return abi.PYINS_E_CONFIG_NAV
    return abi.PYINS_OK

