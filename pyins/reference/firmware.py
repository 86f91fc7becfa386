"""The firmware instance: configuration checks, mode, one step per sample.

Mirrors ``csrc/src/firmware.{hpp,cpp}`` (and the status codes of
``csrc/include/pyins_core.h``). Configurations, samples and outputs use the
C structs' field names, so a record from either engine reads the same.
Sample-level faults (NaN/Inf, saturation, seq gaps, duplicates, lost
sequences, encoder jumps) follow docs/core.md, "Sample-level faults":
``step(..., seq)`` returns the same statuses (negative: rejected, positive:
a notice) and the record carries the same bits and counters.
"""
import math

import numpy as np

from . import attitude, coarse_align, earth, fine_align, indexing, moving_align, strapdown
from .attitude import cross

# Status codes: pinned values of enum pyins_status.
PYINS_OK = 0
PYINS_E_NULL = -1
PYINS_E_MISALIGNED = -2
PYINS_E_MEM_TOO_SMALL = -3
PYINS_E_NOT_INIT = -4
PYINS_E_SAMPLE_NONFINITE = -5
PYINS_E_BAD_ARG = -6
PYINS_E_BUFFER_TOO_SMALL = -7
PYINS_E_CONFIG_RATE = -10
PYINS_E_CONFIG_LAT = -11
PYINS_E_CONFIG_LON = -12
PYINS_E_CONFIG_HEIGHT = -13
PYINS_E_CONFIG_VEL = -14
PYINS_E_CONFIG_ATT = -15
PYINS_E_CONFIG_MODE = -16
PYINS_E_CONFIG_ALIGN_RATIO = -17
PYINS_E_CONFIG_ALIGN_EARLY = -18
PYINS_E_CONFIG_ALIGN_LONG = -19
PYINS_E_CONFIG_ALIGN_TICKS = -20
PYINS_E_CONFIG_FINE = -21
PYINS_E_CONFIG_NOISE = -22
PYINS_E_CONFIG_INDEX_SCHEME = -23
PYINS_E_CONFIG_INDEX_EMPTY = -24
PYINS_E_CONFIG_INDEX_RATE = -25
PYINS_E_CONFIG_INDEX_DELTA = -26
PYINS_E_CONFIG_INDEX_STEP = -27
PYINS_E_SNAPSHOT_SIZE = -28
PYINS_E_SNAPSHOT_VERSION = -29
PYINS_E_SNAPSHOT_CORRUPT = -30
PYINS_E_SAMPLE_SATURATED = -31
PYINS_E_CONFIG_SATURATION = -32
PYINS_E_CONFIG_SEQ = -33
PYINS_E_CONFIG_INDEX_SUMS = -34
PYINS_E_CONFIG_LEVER = -35
PYINS_E_CONFIG_COARSE_METHOD = -36
PYINS_E_CONFIG_INTEGRITY = -37
PYINS_W_SEQ_GAP = 1          #: notices: the sample was handled (docs/core.md)
PYINS_W_SEQ_REPEAT = 2
PYINS_W_SEQ_LOST = 3
PYINS_W_ENCODER_JUMP = 4

INDEX_NONE, INDEX_SINGLE_FWD_REV, INDEX_TWO_POSITION, INDEX_FOUR_POSITION = 0, 1, 2, 3
INDEX_FLEXIBLE_TWO, INDEX_CUSTOM, INDEX_FLEXIBLE_DERIVED = 4, 5, 6

FINE_FEEDBACK = 0      #: PYINS_FINE_FEEDBACK
FINE_OPEN_LOOP = 1     #: PYINS_FINE_OPEN_LOOP
FAULT_KF_NOT_PD = 1    #: PYINS_FAULT_KF_NOT_PD
FAULT_ALIGN_RESTARTED = 2  #: PYINS_FAULT_ALIGN_RESTARTED
FAULT_SAMPLE_NONFINITE = 4   #: PYINS_FAULT_SAMPLE_NONFINITE
FAULT_SAMPLE_SATURATED = 8   #: PYINS_FAULT_SAMPLE_SATURATED
FAULT_SEQ_GAP = 16           #: PYINS_FAULT_SEQ_GAP
FAULT_SEQ_REPEAT = 32        #: PYINS_FAULT_SEQ_REPEAT
FAULT_SEQ_LOST = 64          #: PYINS_FAULT_SEQ_LOST
FAULT_ENCODER_JUMP = 128     #: PYINS_FAULT_ENCODER_JUMP
FAULT_ALIGN_INCONSISTENT = 256   #: PYINS_FAULT_ALIGN_INCONSISTENT
FAULT_COARSE_UNSETTLED = 512     #: PYINS_FAULT_COARSE_UNSETTLED

SEQ_OFF = 0                  #: PYINS_SEQ_OFF
SEQ_CHECK = 1                #: PYINS_SEQ_CHECK
SEQ_NEXT, SEQ_GAP, SEQ_REPEAT, SEQ_LOST = 0, 1, 2, 3   #: SeqKind
U32 = 0xFFFFFFFF

MODE_IDLE = 0          #: Mode::kIdle
MODE_COARSE_ALIGN = 1  #: Mode::kCoarseAlign
MODE_FINE_ALIGN = 2    #: Mode::kFineAlign
MODE_NAVIGATE = 3      #: Mode::kNavigate

STATE_ATT_VALID = 1    #: PYINS_STATE_ATT_VALID

DEFAULT_COARSE_FIRST_S = 20     #: kDefaultCoarseFirstS
DEFAULT_COARSE_EVERY_S = 1      #: kDefaultCoarseEveryS
DEFAULT_COARSE_RATIO = 0.5      #: kDefaultCoarseRatio
DEFAULT_FINE_STATES = 5         #: kDefaultFineStates
DEFAULT_FINE_MEAS_EVERY = 10    #: kDefaultFineMeasEvery
DEFAULT_MOVING_MEAS_EVERY_SECOND = 1   #: kDefaultMovingMeasEverySecond
DEFAULT_POS_SIGMA = 0.5         #: kDefaultPosSigma [m]
DEFAULT_SIGMA0_VEL = 0.5        #: kDefaultSigma0Vel [m/s]
DEFAULT_MOVING_SIGMA_ATT = (1.0 * (np.pi / 180.0 / 60.0), 1.0 * (np.pi / 180.0 / 60.0),
                            10.0 * (np.pi / 180.0 / 60.0))   #: kDefaultMovingSigmaAtt
DEFAULT_FINE_ARW = 0.001 * (np.pi / 180.0) / 60.0           #: kDefaultFineArw
DEFAULT_FINE_VRW = 10.0e-6 * 9.80665                        #: kDefaultFineVrw
ARCMIN_RAD = np.pi / 180.0 / 60.0                           #: kArcminRad
DEFAULT_FINE_SIGMA_ATT = (100.0 * ARCMIN_RAD, 100.0 * ARCMIN_RAD, 600.0 * ARCMIN_RAD)
DEFAULT_COARSE_WANDER = 30.0 * ARCMIN_RAD                   #: kDefaultCoarseWander
VALID_HEADING_SIGMA = 10.0 * ARCMIN_RAD                     #: kValidHeadingSigma
DEFAULT_FINE_SIGMA_GYRO = 0.01 * (np.pi / 180.0) / 3600.0   #: kDefaultFineSigmaGyro
DEFAULT_FINE_SIGMA_ACCEL = 100.0e-6 * 9.80665               #: kDefaultFineSigmaAccel
DEG = np.pi / 180.0                                         #: kDeg
DEFAULT_INDEX_RATE = 6.0 * DEG          #: kDefaultIndexRate
DEFAULT_INDEX_ACCEL = 30.0 * DEG        #: kDefaultIndexAccel
DEFAULT_INDEX_DELTA = 0.01              #: kDefaultIndexDelta
DEFAULT_INDEX_MAX_FLEX = 720.0 * DEG    #: kDefaultIndexMaxFlex
DEFAULT_INDEX_TOLERANCE = 0.5 * DEG     #: kDefaultIndexTolerance
DEFAULT_INDEX_JUMP = 5.0 * DEG          #: kDefaultIndexJump
DEFAULT_INDEX_TIMEOUT_S = 2             #: kDefaultIndexTimeoutS
DEFAULT_STOP_SEED003_S = 60             #: kDefaultStopSeed003S
DEFAULT_STOP_S = 300                    #: kDefaultStopS
DEFAULT_SAT_GYRO_RATE = 400.0 * DEG     #: kDefaultSatGyroRate [rad/s]
DEFAULT_SAT_ACCEL = 20.0 * 9.80665      #: kDefaultSatAccel [m/s^2]
DEFAULT_SEQ_MAX_GAP = 2                 #: kDefaultSeqMaxGap [ticks]
MAX_SEQ_GAP = 100                       #: kMaxSeqGap [ticks]
COUNTERS = ("n_nonfinite", "n_saturated", "n_seq_gaps", "n_seq_bridged", "n_seq_repeats",
            "n_seq_lost", "n_encoder_jumps")   #: SampleCounts, as named in pyins_output

DEFAULT_TICK_HZ = 100          #: kDefaultTickHz
MAX_TICK_HZ = 10000            #: kMaxTickHz
MAX_LAT_RAD = 89.9 * np.pi / 180.0   #: kMaxLatRad
MAX_LEVER_M = 100.0            #: kMaxLeverM
COARSE_TRIAD = coarse_align.METHOD_TRIAD   #: PYINS_COARSE_TRIAD
COARSE_FIT = coarse_align.METHOD_FIT       #: PYINS_COARSE_FIT
DEFAULT_NIS_WINDOW = 100                   #: kDefaultNisWindow
DEFAULT_NIS_MAX = 4.0                      #: kDefaultNisMax

TWO_PI = 2.0 * np.pi


def config_default():
    """Default configuration as a dict (equal to a zeroed C struct)."""
    return {
        "tick_hz": DEFAULT_TICK_HZ,
        "vertical_mode": strapdown.VERTICAL_HOLD,
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
        "fine_correction": FINE_FEEDBACK,
        "fine_gyro_arw": 0.0,
        "fine_accel_vrw": 0.0,
        "fine_sigma0_att_rad": np.zeros(3),
        "fine_sigma0_gyro": 0.0,
        "fine_sigma0_accel": 0.0,
        "index_scheme": INDEX_NONE,
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
        "seq_mode": SEQ_OFF,
        "seq_max_gap_ticks": 0,
        "sat_gyro_rad": 0.0,
        "sat_accel_mps": 0.0,
        "index_sums": indexing.SUMS_STOPS,
        "reserved1": 0,
        "lever_b_m": np.zeros(3),
        "lever_p_m": np.zeros(3),
        "coarse_method": COARSE_TRIAD,
        "reserved2": 0,
        "integrity_nis_window": 0,
        "reserved3": 0,
        "integrity_nis_max": 0.0,
        "integrity_coarse_rad": 0.0,
        "fine_pos_sigma_m": 0.0,
        "fine_sigma0_vel_mps": 0.0,
    }


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
    if cfg["index_scheme"] != INDEX_CUSTOM:
        if cfg["index_stop_ticks"] == 0:
            s = DEFAULT_STOP_SEED003_S if cfg["index_scheme"] == INDEX_SINGLE_FWD_REV else DEFAULT_STOP_S
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
    return cfg


def index_check(cfg):
    """The indexing part of config_check (mirrors index_check)."""
    scheme = cfg["index_scheme"]
    if scheme < INDEX_NONE or scheme > INDEX_FLEXIBLE_DERIVED:
        return PYINS_E_CONFIG_INDEX_SCHEME
    if scheme == INDEX_NONE:
        return PYINS_OK
    flexible = scheme in (INDEX_FLEXIBLE_TWO, INDEX_FLEXIBLE_DERIVED)
    if scheme == INDEX_CUSTOM:
        n = cfg["index_n_steps"]
        if n < 1 or n > indexing.MAX_STEPS:
            return PYINS_E_CONFIG_INDEX_EMPTY
        for stop, kind, angle in list(cfg["index_steps"])[:n]:
            if (stop < 1 or not math.isfinite(angle) or kind not in (1, 2, 3)
                    or (kind == indexing.KIND_FIXED and angle == 0.0) or abs(angle) > 16.0 * np.pi):
                return PYINS_E_CONFIG_INDEX_STEP
            flexible = flexible or kind != indexing.KIND_FIXED
    elif cfg["index_stop_ticks"] < 1:
        return PYINS_E_CONFIG_INDEX_STEP
    rate, accel = cfg["index_rate_rad_s"], cfg["index_accel_rad_s2"]
    if not (rate > 0.0) or not (accel > 0.0) or not math.isfinite(rate) or not math.isfinite(accel):
        return PYINS_E_CONFIG_INDEX_RATE
    if flexible and not (0.0 < cfg["index_delta"] < 1.0):
        return PYINS_E_CONFIG_INDEX_DELTA
    vals = [cfg["index_max_flex_rad"], cfg["index_tolerance_rad"], cfg["index_jump_rad"]]
    if any(not (v > 0.0) or not math.isfinite(v) for v in vals) or cfg["index_timeout_ticks"] < 1:
        return PYINS_E_CONFIG_INDEX_STEP
    return PYINS_OK


def _finite3(v):
    return all(math.isfinite(x) for x in v)


def config_check(raw):
    """PYINS_OK or the first PYINS_E_CONFIG_* that applies (mirrors config_check)."""
    if raw["tick_hz"] < 0 or raw["tick_hz"] > MAX_TICK_HZ:
        return PYINS_E_CONFIG_RATE
    cfg = config_resolved(raw)
    if not math.isfinite(cfg["lat_rad"]) or abs(cfg["lat_rad"]) > MAX_LAT_RAD:
        return PYINS_E_CONFIG_LAT
    if not math.isfinite(cfg["lon_rad"]) or abs(cfg["lon_rad"]) > 2.0 * TWO_PI:
        return PYINS_E_CONFIG_LON
    h = cfg["height_m"]
    if not math.isfinite(h) or h < -1e4 or h > 1e5:
        return PYINS_E_CONFIG_HEIGHT
    v = cfg["vel_n_mps"]
    if not _finite3(v) or abs(v[0]) > 1e4 or abs(v[1]) > 1e4 or abs(v[2]) > 1e4:
        return PYINS_E_CONFIG_VEL
    if not _finite3(cfg["euler_b_rad"]) or not math.isfinite(cfg["table_angle_rad"]):
        return PYINS_E_CONFIG_ATT
    if cfg["vertical_mode"] not in (strapdown.VERTICAL_HOLD, strapdown.VERTICAL_FREE):
        return PYINS_E_CONFIG_MODE
    if cfg["coarse_ticks"] < 0 or cfg["coarse_first_output_ticks"] < 0 or cfg["coarse_output_every_ticks"] < 0:
        return PYINS_E_CONFIG_ALIGN_TICKS
    if not (0.0 < cfg["coarse_ratio"] < 1.0):
        return PYINS_E_CONFIG_ALIGN_RATIO
    if cfg["coarse_ticks"] > 0:
        every = cfg["coarse_output_every_ticks"]
        if cfg["coarse_first_output_ticks"] > cfg["coarse_ticks"]:
            return PYINS_E_CONFIG_ALIGN_TICKS
        if cfg["coarse_ratio"] * float(cfg["coarse_first_output_ticks"]) < float(every):
            return PYINS_E_CONFIG_ALIGN_EARLY
        if (cfg["coarse_method"] == COARSE_TRIAD
                and cfg["coarse_ticks"] // every > coarse_align.HIST_LEN - 1):
            return PYINS_E_CONFIG_ALIGN_LONG
    if cfg["fine_ticks"] < 0:
        return PYINS_E_CONFIG_ALIGN_TICKS
    if (cfg["fine_states"] not in (5, 8, 12) or cfg["fine_meas_every_ticks"] < 0
            or cfg["fine_correction"] not in (FINE_FEEDBACK, FINE_OPEN_LOOP)):
        return PYINS_E_CONFIG_FINE
    noise = [cfg["fine_gyro_arw"], cfg["fine_accel_vrw"], *cfg["fine_sigma0_att_rad"],
             cfg["fine_sigma0_gyro"], cfg["fine_sigma0_accel"], cfg["fine_pos_sigma_m"],
             cfg["fine_sigma0_vel_mps"]]
    for v in noise:
        if not (v > 0.0) or not math.isfinite(v):
            return PYINS_E_CONFIG_NOISE
    index_status = index_check(cfg)
    if index_status != PYINS_OK:
        return index_status
    if cfg["index_sums"] not in (indexing.SUMS_STOPS, indexing.SUMS_ALL):
        return PYINS_E_CONFIG_INDEX_SUMS
    if cfg["seq_mode"] not in (SEQ_OFF, SEQ_CHECK) or not 1 <= cfg["seq_max_gap_ticks"] <= MAX_SEQ_GAP:
        return PYINS_E_CONFIG_SEQ
    sat = (cfg["sat_gyro_rad"], cfg["sat_accel_mps"])
    if any(not (v > 0.0) or not math.isfinite(v) for v in sat):
        return PYINS_E_CONFIG_SATURATION
    for r in (cfg["lever_b_m"], cfg["lever_p_m"]):
        if not _finite3(r) or r[0] * r[0] + r[1] * r[1] + r[2] * r[2] > MAX_LEVER_M * MAX_LEVER_M:
            return PYINS_E_CONFIG_LEVER
    if cfg["coarse_method"] not in (COARSE_TRIAD, COARSE_FIT):
        return PYINS_E_CONFIG_COARSE_METHOD
    if (cfg["coarse_method"] == COARSE_FIT and cfg["coarse_ticks"] > 0
            and cfg["coarse_first_output_ticks"] // cfg["coarse_output_every_ticks"]
            < coarse_align.FIT_MIN_INTERVALS):
        return PYINS_E_CONFIG_ALIGN_EARLY
    nis_max, wander = cfg["integrity_nis_max"], cfg["integrity_coarse_rad"]
    if (cfg["integrity_nis_window"] < -1 or not (nis_max > 0.0) or not math.isfinite(nis_max)
            or not (wander > 0.0) or not math.isfinite(wander)):
        return PYINS_E_CONFIG_INTEGRITY
    return PYINS_OK


def wrap_two_pi(a):
    """Angle in [0, 2 pi) for any finite input (mirrors wrap_two_pi: a
    rounding to 2 pi or below 0, or a too large to wrap, gives 0)."""
    if 0.0 <= a < TWO_PI:
        return a
    w = a - TWO_PI * math.floor(a / TWO_PI)
    if not (0.0 <= w < TWO_PI):
        w = 0.0
    return w


def wrap_pi(a):
    """Angle in (-pi, pi] for an input within (-3 pi, 3 pi]."""
    if a > np.pi:
        return a - TWO_PI
    if a <= -np.pi:
        return a + TWO_PI
    return a


def saturated3(v, limit):
    """Some component at or beyond the limit (mirrors saturated3)."""
    return abs(v[0]) >= limit or abs(v[1]) >= limit or abs(v[2]) >= limit


def count(counter, n=1):
    """counter + n, saturating at 2^32 - 1 (mirrors count)."""
    return U32 if n > U32 - counter else counter + n


class Firmware:
    """NumPy mirror of ``pyins::firmware::Firmware``.

    ``Firmware(cfg)`` with a dict like :func:`config_default`; raises
    ValueError if :func:`config_check` refuses it.
    """

    def __init__(self, cfg=None):
        full = config_default()
        if cfg:
            full.update(cfg)
        status = config_check(full)
        if status != PYINS_OK:
            raise ValueError(f"configuration refused with status {status}")
        self.init(full)

    def init(self, raw):
        cfg = config_resolved(raw)
        self.cfg = cfg
        self.dt = 1.0 / float(cfg["tick_hz"])
        self.mode = MODE_IDLE
        self.att_valid = cfg["coarse_ticks"] == 0
        self.kf_states = 0
        self.fine_tick = 0
        self.align_restarts = 0
        self.gap_pending = False
        self.faults = 0
        self.fine = None
        self.tick = 0
        self.table_angle = cfg["table_angle_rad"]
        self.encoder = wrap_two_pi(cfg["table_angle_rad"])
        self.enc_sin_half = math.sin(0.5 * self.encoder)
        self.enc_cos_half = math.cos(0.5 * self.encoder)
        self.seq = 0
        self.seq_valid = False
        self.last_dtheta = np.zeros(3)
        self.last_dv = np.zeros(3)
        self.counts = dict.fromkeys(COUNTERS, 0)
        self.lever_b = np.array(cfg["lever_b_m"], dtype=float)
        self.lever_pp = np.array(cfg["lever_p_m"], dtype=float)
        self.has_lever = 1 if (np.any(self.lever_b != 0.0) or np.any(self.lever_pp != 0.0)) else 0
        self.rate_count = 0
        self.rate_p = np.zeros(3)
        self.alpha_rate = 0.0
        self.prev_dtheta = np.zeros(3)
        self.prev_dalpha = 0.0
        self.lever_vel_n = np.zeros(3)
        self.lever_refine = 0
        self.integrity_lost = 0
        wander = cfg["integrity_coarse_rad"]
        self.coarse_wander_max = 1.0 if wander >= 0.5 * np.pi else math.sin(wander)
        euler_b = np.array(cfg["euler_b_rad"], dtype=float)
        mat_np = attitude.euler_to_mat(euler_b) @ attitude.rot_z(self.encoder)
        lon = cfg["lon_rad"]
        if lon > np.pi or lon <= -np.pi:
            lon = wrap_pi(wrap_two_pi(lon))
        nav = strapdown.NavState(cfg["lat_rad"], lon, cfg["height_m"],
                                 np.array(cfg["vel_n_mps"], dtype=float),
                                 attitude.mat_to_quat(mat_np))
        self.sd = strapdown.make_strapdown(nav, cfg["vertical_mode"])
        if cfg["index_scheme"] == INDEX_CUSTOM:
            steps = [indexing.Step(int(s), int(k), float(a))
                     for s, k, a in list(cfg["index_steps"])[:cfg["index_n_steps"]]]
        else:
            steps = indexing.preset_steps(cfg["index_scheme"], cfg["index_stop_ticks"])
        self.index_prm = indexing.Params(
            steps=steps, rate=cfg["index_rate_rad_s"], accel=cfg["index_accel_rad_s2"],
            delta=cfg["index_delta"], max_flex=cfg["index_max_flex_rad"],
            tolerance=cfg["index_tolerance_rad"], jump=cfg["index_jump_rad"],
            timeout_ticks=cfg["index_timeout_ticks"], dt=self.dt, sums=cfg["index_sums"])
        idle = indexing.Params(**{**self.index_prm.__dict__, "steps": []})
        self.idx = indexing.init(idle, self.table_angle)
        self.coarse = None
        if cfg["coarse_ticks"] > 0:
            sin_lat, cos_lat = np.sin(cfg["lat_rad"]), np.cos(cfg["lat_rad"])
            prm = coarse_align.Params(
                method=cfg["coarse_method"], lever=self.has_lever, ratio=cfg["coarse_ratio"], first_output=cfg["coarse_first_output_ticks"],
                output_every=cfg["coarse_output_every_ticks"], dt=self.dt, sin_lat=sin_lat,
                cos_lat=cos_lat, gravity=earth.normal_gravity(sin_lat, cfg["height_m"]),
                settle_from=cfg["coarse_ticks"] - cfg["coarse_ticks"] // 5)
            self.coarse = coarse_align.init(prm)

    def end_coarse(self):
        """Navigation starts from the coarse attitude, at rest, with its history."""
        nav = self.sd.nav
        nav = strapdown.NavState(nav.lat, nav.lon, nav.height, np.zeros(3),
                                 attitude.mat_to_quat(coarse_align.mat_n_p(self.coarse)))
        self.sd = strapdown.make_strapdown(nav, self.sd.vertical)
        self.sd.hist = self.coarse.hist
        if self.has_lever:
            self.place_imu(self.cfg["lat_rad"], self.sd.ref_lon, self.cfg["height_m"], np.zeros(3))
        self.att_valid = True
        if self.cfg["fine_ticks"] > 0:
            self.start_fine()
        else:
            self.start_navigation()

    def start_fine(self):
        cfg = self.cfg
        sin_lat, cos_lat = np.sin(cfg["lat_rad"]), np.cos(cfg["lat_rad"])
        prm = fine_align.Params(
            sin_lat=sin_lat, cos_lat=cos_lat, gravity=earth.normal_gravity(sin_lat, cfg["height_m"]),
            dt=self.dt, meas_every=cfg["fine_meas_every_ticks"], gyro_arw=cfg["fine_gyro_arw"],
            accel_vrw=cfg["fine_accel_vrw"], sigma0_att=np.array(cfg["fine_sigma0_att_rad"], dtype=float),
            sigma0_gyro=cfg["fine_sigma0_gyro"], sigma0_accel=cfg["fine_sigma0_accel"],
            nis_window=max(cfg["integrity_nis_window"], 0), nis_max=cfg["integrity_nis_max"])
        self.kf_states = cfg["fine_states"]
        self.fine_tick = 0
        if self.kf_states == 12:
            rm, rn = earth.principal_radii(sin_lat)
            mp = moving_align.Params(
                sin_lat=sin_lat, cos_lat=cos_lat, rm_h=rm + cfg["height_m"], rn_h=rn + cfg["height_m"],
                dt=self.dt, meas_every=cfg["fine_meas_every_ticks"], gyro_arw=cfg["fine_gyro_arw"],
                accel_vrw=cfg["fine_accel_vrw"], pos_sigma=cfg["fine_pos_sigma_m"],
                sigma0_att=np.array(cfg["fine_sigma0_att_rad"], dtype=float),
                sigma0_vel=cfg["fine_sigma0_vel_mps"], sigma0_gyro=cfg["fine_sigma0_gyro"],
                sigma0_accel=cfg["fine_sigma0_accel"], nis_window=prm.nis_window, nis_max=prm.nis_max)
        if self.has_lever:
            self.lever_vel_n = attitude.quat_to_mat(self.sd.nav.quat_np) @ self.lever_vel_p()
        self.fine = moving_align.init(mp) if self.kf_states == 12 else fine_align.init(self.kf_states, prm)
        self.mode = MODE_FINE_ALIGN

    def fine_phi(self):
        if self.mode != MODE_FINE_ALIGN:
            return np.zeros(3)
        return fine_align.phi(self.fine)

    def apply_fine_correction(self):
        """C_p^n = (I + phi x) C_p^n': rotate by phi^ in n, then phi^ = 0."""
        phi = self.fine_phi()
        q_phi = attitude.rotvec_to_quat(phi)
        self.sd.nav.quat_np = attitude.quat_normalize(attitude.quat_mul(q_phi, self.sd.nav.quat_np))
        if self.has_lever:
            # the lever velocity in n turns with the attitude (see firmware.cpp)
            self.lever_vel_n = attitude.quat_to_mat(q_phi) @ self.lever_vel_n
        if self.kf_states == 12:
            x = self.fine.x
            nav = self.sd.nav
            cos_lat = np.cos(nav.lat)
            nav.vel_n[0] = nav.vel_n[0] - x[moving_align.VEL]
            nav.vel_n[1] = nav.vel_n[1] - x[moving_align.VEL + 1]
            nav.lat = nav.lat - x[moving_align.POS + 1] / self.fine.prm.rm_h
            nav.lon = wrap_pi(nav.lon - x[moving_align.POS] / (self.fine.prm.rn_h * cos_lat))
            moving_align.reset_feedback(self.fine)
        else:
            fine_align.reset_phi(self.fine)

    def fine_heading_known(self):
        """The fine filter's heading sigma is within VALID_HEADING_SIGMA (mirrors fine_heading_known)."""
        return self.fine.p[2, 2] <= VALID_HEADING_SIGMA * VALID_HEADING_SIGMA

    def end_fine(self):
        if not self.fine_heading_known():
            self.att_valid = False
        self.apply_fine_correction()
        if self.has_lever and self.kf_states != 12:
            self.place_imu(self.cfg["lat_rad"], self.sd.ref_lon, self.cfg["height_m"], np.zeros(3))
        self.start_navigation()

    def start_navigation(self):
        self.mode = MODE_NAVIGATE
        self.idx = indexing.init(self.index_prm, self.table_angle)

    def imu_yaw(self):
        """psi_p = psi_b + alpha (mirrors Firmware::imu_yaw)."""
        q_pb = np.array([self.enc_cos_half, 0.0, 0.0, -self.enc_sin_half])
        w, x, y, z = attitude.quat_mul(self.sd.nav.quat_np, q_pb)
        c01 = 2.0 * (x * y - w * z)
        c11 = w * w - x * x + y * y - z * z
        return wrap_pi(np.arctan2(-c01, c11) + self.encoder)

    def update_rates(self, dtheta_p, dalpha):
        """Rates at the end of the tick, second order (mirrors update_rates)."""
        if self.rate_count == 0:
            self.rate_p = dtheta_p / self.dt
            self.alpha_rate = dalpha / self.dt
        else:
            self.rate_p = (1.5 * dtheta_p - 0.5 * self.prev_dtheta) / self.dt
            self.alpha_rate = (1.5 * dalpha - 0.5 * self.prev_dalpha) / self.dt
        self.prev_dtheta = np.array(dtheta_p, dtype=float)
        self.prev_dalpha = dalpha
        if self.rate_count < 2:
            self.rate_count = self.rate_count + 1

    def _lever_b_p(self):
        """Rz(alpha)^T lever_b from the cached half-angle."""
        sa = 2.0 * self.enc_sin_half * self.enc_cos_half
        ca = self.enc_cos_half * self.enc_cos_half - self.enc_sin_half * self.enc_sin_half
        lb = self.lever_b
        return np.array([ca * lb[0] + sa * lb[1], -sa * lb[0] + ca * lb[1], lb[2]])

    def lever_p(self):
        """r^p = Rz(alpha)^T lever_b + lever_p (mirrors Firmware::lever_p)."""
        return self._lever_b_p() + self.lever_pp

    def lever_vel_p(self):
        """u^p at the last tick's rates (mirrors lever_vel_p)."""
        return self.lever_vel_for(self.rate_p, self.alpha_rate)

    def lever_vel_for(self, rate_p, alpha_rate):
        """u^p = (w_ip^p - alpha' z) x Rz^T lever_b + w_ip^p x lever_p (mirrors lever_vel_for)."""
        w_b = rate_p - np.array([0.0, 0.0, alpha_rate])
        return cross(w_b, self._lever_b_p()) + cross(rate_p, self.lever_pp)

    def lever_vel_e_n(self, mat_np):
        """C_p^n u^p - w_ie^n x C_p^n r^p (mirrors lever_vel_e_n)."""
        lat = self.sd.nav.lat
        w_ie_n = np.array([0.0, earth.OMEGA_IE * np.cos(lat), earth.OMEGA_IE * np.sin(lat)])
        return mat_np @ self.lever_vel_p() - cross(w_ie_n, mat_np @ self.lever_p())

    def place_imu(self, lat, lon, height, vel_n):
        """The navigation state on the accelerometers of a reference point (mirrors place_imu)."""
        mat_np = attitude.quat_to_mat(self.sd.nav.quat_np)
        d = mat_np @ self.lever_p()
        sin_lat, cos_lat = np.sin(lat), np.cos(lat)
        rm, rn = earth.principal_radii(sin_lat)
        nav = self.sd.nav
        nav.lat = lat + d[1] / (rm + height)
        nav.lon = wrap_pi(lon + d[0] / ((rn + height) * cos_lat))
        nav.height = height + d[2]
        nav.vel_n = np.array(vel_n, dtype=float) + self.lever_vel_e_n(mat_np)
        if self.sd.vertical == strapdown.VERTICAL_HOLD:
            nav.vel_n[2] = 0.0
            self.sd.ref_height = nav.height

    def reference_point(self):
        """(lat, lon, height, vel_n) of the reference point (mirrors reference_point)."""
        nav = self.sd.nav
        mat_np = attitude.quat_to_mat(nav.quat_np)
        d = mat_np @ self.lever_p()
        sin_lat, cos_lat = np.sin(nav.lat), np.cos(nav.lat)
        rm, rn = earth.principal_radii(sin_lat)
        vel = nav.vel_n - self.lever_vel_e_n(mat_np)
        lat = nav.lat - d[1] / (rm + nav.height)
        lon = wrap_pi(nav.lon - d[0] / ((rn + nav.height) * cos_lat))
        return lat, lon, nav.height - d[2], vel

    def moving_fine(self, dtheta_p, dv_p):
        """One tick of the moving-base fine alignment (mirrors moving_fine)."""
        dv_sf_n = strapdown.update(self.sd, dtheta_p, dv_p, self.dt)
        z = (0.0, 0.0)
        if moving_align.measure(self.fine):
            lat, lon = self.sd.nav.lat, self.sd.nav.lon
            if self.has_lever:
                lat, lon, _, _ = self.reference_point()
            z = (wrap_pi(lon - self.sd.ref_lon) * self.fine.prm.rn_h * self.fine.prm.cos_lat,
                 (lat - self.cfg["lat_rad"]) * self.fine.prm.rm_h)
        updated = moving_align.step(self.fine, dv_sf_n, z)
        if not self.fine.healthy:
            self.faults = self.faults | FAULT_KF_NOT_PD
        if not self.fine.consistent:
            self.faults = self.faults | FAULT_ALIGN_INCONSISTENT
            self.integrity_lost = 1
        if updated:
            self.apply_fine_correction()
        self.fine_tick = self.fine_tick + 1
        if self.fine_tick == self.cfg["fine_ticks"]:
            self.end_fine()

    def index_reset(self):
        if self.idx.state == indexing.STATE_FAULT:
            self.idx = indexing.reset(self.idx, self.table_angle)

    def hold_at_site(self):
        self.sd.nav.lat = self.cfg["lat_rad"]
        self.sd.nav.lon = self.sd.ref_lon
        self.sd.nav.height = self.cfg["height_m"]
        self.sd.nav.vel_n = np.zeros(3)
        self.sd.prev_dvel_n = np.zeros(3)
        if self.has_lever:
            self.place_imu(self.cfg["lat_rad"], self.sd.ref_lon, self.cfg["height_m"], np.zeros(3))

    def reject(self, fault_bit, counter):
        """A rejected sample: sticky bit, counter, alignment restart (mirrors reject)."""
        self.faults = self.faults | fault_bit
        self.counts[counter] = count(self.counts[counter])
        if self.mode in (MODE_COARSE_ALIGN, MODE_FINE_ALIGN):
            self.gap_pending = True
            self.faults = self.faults | FAULT_ALIGN_RESTARTED

    def seq_step(self, seq):
        """(kind, missing ticks) of a sample's seq (mirrors Firmware::seq_step)."""
        if self.cfg["seq_mode"] != SEQ_CHECK or not self.seq_valid:
            return SEQ_NEXT, 0
        d = (seq - self.seq) & U32
        g = self.cfg["seq_max_gap_ticks"]
        if d == 0 or d >= ((0 - g) & U32):
            return SEQ_REPEAT, 0
        if d > g + 1:
            return SEQ_LOST, (d - 1 if d < 0x80000000 else 0)
        if d > 1:
            return SEQ_GAP, d - 1
        return SEQ_NEXT, 0

    def usable(self, dtheta_p, dv_p, table_angle_rad):
        """Finite and within the saturation limits (mirrors Firmware::usable)."""
        return (_finite3(dtheta_p) and _finite3(dv_p) and math.isfinite(table_angle_rad)
                and not saturated3(dtheta_p, self.cfg["sat_gyro_rad"])
                and not saturated3(dv_p, self.cfg["sat_accel_mps"]))

    def ticks_for(self, dtheta_p, dv_p, table_angle_rad, seq=0):
        """Ticks stepping this sample would add (0: rejected or dropped); changes nothing."""
        if not self.usable(dtheta_p, dv_p, table_angle_rad):
            return 0
        kind, missing = self.seq_step(int(seq) & U32)
        return 0 if kind == SEQ_REPEAT else missing + 1

    def step(self, dtheta_p, dv_p, table_angle_rad, seq=0):
        """One sample; returns ``(status, output dict)`` (mirrors Firmware::step).

        ``seq`` is the IMU's sample counter (read with ``seq_mode`` = SEQ_CHECK).
        """
        if not (_finite3(dtheta_p) and _finite3(dv_p) and math.isfinite(table_angle_rad)):
            self.reject(FAULT_SAMPLE_NONFINITE, "n_nonfinite")
            return PYINS_E_SAMPLE_NONFINITE, self.output()
        if saturated3(dtheta_p, self.cfg["sat_gyro_rad"]) or saturated3(dv_p, self.cfg["sat_accel_mps"]):
            self.reject(FAULT_SAMPLE_SATURATED, "n_saturated")
            return PYINS_E_SAMPLE_SATURATED, self.output()
        seq = int(seq) & U32
        status = PYINS_OK
        kind, missing = self.seq_step(seq)
        if kind == SEQ_REPEAT:
            self.faults = self.faults | FAULT_SEQ_REPEAT
            self.counts["n_seq_repeats"] = count(self.counts["n_seq_repeats"])
            return PYINS_W_SEQ_REPEAT, self.output()
        resync = kind == SEQ_LOST
        if resync:
            self.faults = self.faults | FAULT_SEQ_LOST
            self.counts["n_seq_lost"] = count(self.counts["n_seq_lost"])
            status = PYINS_W_SEQ_LOST
        elif kind == SEQ_GAP:
            self.faults = self.faults | FAULT_SEQ_GAP
            self.counts["n_seq_gaps"] = count(self.counts["n_seq_gaps"])
            status = PYINS_W_SEQ_GAP
        dtheta_p = np.array(dtheta_p, dtype=float)
        dv_p = np.array(dv_p, dtype=float)
        encoder = wrap_two_pi(table_angle_rad)
        if (self.mode != MODE_IDLE and not resync
                and abs(wrap_pi(encoder - self.encoder)) > self.cfg["index_jump_rad"] * float(missing + 1)):
            self.faults = self.faults | FAULT_ENCODER_JUMP
            self.counts["n_encoder_jumps"] = count(self.counts["n_encoder_jumps"])
            if status == PYINS_OK:
                status = PYINS_W_ENCODER_JUMP
        if missing > 0 or resync:
            if self.mode in (MODE_COARSE_ALIGN, MODE_FINE_ALIGN):
                self.gap_pending = True
                self.faults = self.faults | FAULT_ALIGN_RESTARTED
                self.tick = self.tick + missing
            elif resync:
                self.tick = self.tick + missing
            else:
                self.bridge(missing, dtheta_p, dv_p, encoder)
                self.counts["n_seq_bridged"] = count(self.counts["n_seq_bridged"], missing)
        self.advance(dtheta_p, dv_p, encoder)
        self.last_dtheta = dtheta_p.copy()
        self.last_dv = dv_p.copy()
        self.seq = seq
        self.seq_valid = True
        return status, self.output()

    def bridge(self, missing, dtheta_p, dv_p, encoder):
        """Interpolate the missing ticks between the last sample and this one (mirrors bridge)."""
        dtheta0 = self.last_dtheta
        dv0 = self.last_dv
        ddtheta = dtheta_p - dtheta0
        ddv = dv_p - dv0
        enc0 = self.encoder
        turn = wrap_pi(encoder - enc0)
        span = float(missing + 1)
        for j in range(1, missing + 1):
            f = float(j) / span
            self.advance(dtheta0 + ddtheta * f, dv0 + ddv * f, wrap_two_pi(enc0 + turn * f))

    def advance(self, dtheta_p, dv_p, encoder):
        """One tick with increments taken as good (mirrors Firmware::advance)."""
        dalpha = wrap_pi(encoder - self.encoder)
        self.table_angle = self.table_angle + dalpha
        if encoder != self.encoder:   # the table moved: refresh the cached half-angle
            self.encoder = encoder
            self.enc_sin_half = math.sin(0.5 * self.encoder)
            self.enc_cos_half = math.cos(0.5 * self.encoder)
        if self.has_lever:
            if self.lever_refine:
                # w(t0) refined with this tick's increments (mirrors advance)
                self.lever_refine = 0
                dw = (self.prev_dtheta - dtheta_p) / (2.0 * self.dt)
                dwa = (self.prev_dalpha - dalpha) / (2.0 * self.dt)
                du = self.lever_vel_for(dw, dwa)   # u is linear in the rates
                dvel = attitude.quat_to_mat(self.sd.nav.quat_np) @ du
                if self.sd.vertical == strapdown.VERTICAL_HOLD:
                    dvel[2] = 0.0
                nav = self.sd.nav
                sin_lat, cos_lat = np.sin(nav.lat), np.cos(nav.lat)
                rm, rn = earth.principal_radii(sin_lat)
                nav.vel_n = nav.vel_n + dvel
                nav.lat = nav.lat + dvel[1] * self.dt / (rm + nav.height)
                nav.lon = wrap_pi(nav.lon + dvel[0] * self.dt / ((rn + nav.height) * cos_lat))
                if self.sd.vertical == strapdown.VERTICAL_FREE:
                    nav.height = nav.height + dvel[2] * self.dt
            self.update_rates(dtheta_p, dalpha)
        if self.gap_pending:
            self.gap_pending = False
            self.align_restarts = self.align_restarts + 1
            if self.cfg["coarse_ticks"] > 0:
                self.coarse = coarse_align.init(self.coarse.prm)
                self.att_valid = False
                self.mode = MODE_COARSE_ALIGN
            else:
                self.start_fine()
        if self.mode == MODE_IDLE:
            if self.cfg["coarse_ticks"] > 0:
                self.mode = MODE_COARSE_ALIGN
            elif self.cfg["fine_ticks"] > 0:
                self.start_fine()
            else:
                self.start_navigation()
                if self.has_lever:
                    self.place_imu(self.cfg["lat_rad"], self.sd.ref_lon, self.cfg["height_m"],
                                   np.array(self.cfg["vel_n_mps"], dtype=float))
                    self.lever_refine = 1
        if self.mode == MODE_COARSE_ALIGN:
            coarse_align.update(self.coarse, dtheta_p, dv_p,
                                self.lever_vel_p() if self.has_lever else np.zeros(3))
            if self.coarse.wander > self.coarse_wander_max:
                self.faults = self.faults | FAULT_COARSE_UNSETTLED
                self.integrity_lost = 1
            if self.coarse.tick == self.cfg["coarse_ticks"]:
                self.end_coarse()
        elif self.mode == MODE_FINE_ALIGN and self.kf_states == 12:
            self.moving_fine(dtheta_p, dv_p)
        elif self.mode == MODE_FINE_ALIGN:
            dv_sf_n = strapdown.update(self.sd, dtheta_p, dv_p, self.dt)
            self.hold_at_site()
            if self.has_lever:
                lat = self.cfg["lat_rad"]
                w_ie_n = np.array([0.0, earth.OMEGA_IE * np.cos(lat), earth.OMEGA_IE * np.sin(lat)])
                lv = attitude.quat_to_mat(self.sd.nav.quat_np) @ self.lever_vel_p()
                dv_sf_n = dv_sf_n - (lv - self.lever_vel_n) - cross(w_ie_n, lv) * self.dt
                self.lever_vel_n = lv
            updated = fine_align.step(self.fine, dv_sf_n)
            if not self.fine.healthy:
                self.faults = self.faults | FAULT_KF_NOT_PD
            if not self.fine.consistent:
                self.faults = self.faults | FAULT_ALIGN_INCONSISTENT
                self.integrity_lost = 1
            if updated and self.cfg["fine_correction"] == FINE_FEEDBACK:
                self.apply_fine_correction()
            self.fine_tick = self.fine_tick + 1
            if self.fine_tick == self.cfg["fine_ticks"]:
                self.end_fine()
        else:
            strapdown.update(self.sd, dtheta_p, dv_p, self.dt)
            if self.index_prm.n_steps > 0:
                indexing.update(self.idx, self.table_angle, self.imu_yaw())
        self.tick = self.tick + 1

    def output(self):
        nav = self.sd.nav
        q_pb = np.array([self.enc_cos_half, 0.0, 0.0, -self.enc_sin_half])
        q_np = nav.quat_np
        valid = self.att_valid
        if self.mode == MODE_COARSE_ALIGN and self.coarse.solved:
            q_np = attitude.mat_to_quat(coarse_align.mat_n_p(self.coarse))
            valid = False   # provisional until the alignment ends and its wander test passed
        elif self.mode == MODE_FINE_ALIGN:
            q_np = attitude.quat_normalize(
                attitude.quat_mul(attitude.rotvec_to_quat(self.fine_phi()), nav.quat_np))
            if ((self.cfg["integrity_nis_window"] > 0 and self.fine.nis_windows == 0)
                    or not self.fine_heading_known()):
                valid = False   # provisional until the first NIS window, and the heading known
        q_nb = attitude.quat_normalize(attitude.quat_mul(q_np, q_pb))
        euler_b = attitude.quat_to_euler(q_nb)
        lat, lon, height, vel = nav.lat, nav.lon, nav.height, nav.vel_n.copy()
        if self.has_lever and self.mode in (MODE_FINE_ALIGN, MODE_NAVIGATE):
            lat, lon, height, vel = self.reference_point()
            if self.sd.vertical == strapdown.VERTICAL_HOLD:
                vel[2] = 0.0
        return {
            "tick": self.tick,
            "mode": self.mode,
            "fault_flags": self.faults,
            "state_flags": STATE_ATT_VALID if valid and not self.integrity_lost else 0,
            "lat_rad": lat,
            "lon_rad": lon,
            "height_m": height,
            "vel_n_mps": vel,
            "quat_nb": q_nb,
            "quat_np": q_np.copy(),
            "euler_b_rad": euler_b,
            "heading_b_rad": attitude.yaw_to_heading(euler_b[2]),
            "yaw_p_rad": wrap_pi(euler_b[2] + self.encoder),
            "table_angle_rad": self.table_angle,
            "index_state": self.idx.state,
            "index_step": self.idx.step,
            "index_fault": self.idx.fault,
            "index_fallbacks": self.idx.fallbacks,
            "motor_rate_cmd_rad_s": self.idx.cmd_rate,
            "table_angle_cmd_rad": self.idx.cmd_angle,
            "index_a_c": self.idx.a_c,
            "index_a_s": self.idx.a_s,
            "kf_states": self.kf_states,
            "align_restarts": self.align_restarts,
            **self.counts,
            "seq": self.seq,
            "align_nis": self.fine.nis_mean if self.fine is not None else 0.0,
            "coarse_wander_rad": self.coarse.wander if self.cfg["coarse_ticks"] > 0 else 0.0,
            "kf_x": self._kf(lambda f: f.x),
            "kf_sigma": self._kf(lambda f: np.sqrt(np.diag(f.p))),
        }

    def _kf(self, get):
        out = np.zeros(8)
        if self.fine is not None:
            v = get(self.fine)
            if len(v) == moving_align.STATES:    # [phi, eps, nabla_E, nabla_N], as the 8-state filter
                v = v[[0, 1, 2, moving_align.EPS, moving_align.EPS + 1, moving_align.EPS + 2,
                       moving_align.NABLA, moving_align.NABLA + 1]]
            out[:len(v)] = v
        return out

    def run(self, dtheta_p, dv_p, table_angle_rad, seq=None):
        """Step through arrays; returns a list of output dicts (raises at a rejected sample)."""
        outs = []
        for k in range(len(dtheta_p)):
            status, out = self.step(dtheta_p[k], dv_p[k], table_angle_rad[k], 0 if seq is None else seq[k])
            if status < 0:
                raise ValueError(f"sample {k} rejected with status {status}")
            outs.append(out)
        return outs
