"""The firmware instance: configuration checks, mode, one step per sample.

Mirrors ``csrc/src/firmware.{hpp,cpp}`` (and the status codes of
``csrc/include/pyins_core.h``). Configurations, samples and outputs use the
C structs' field names, so a record from either engine reads the same.
"""
import math

import numpy as np

from . import attitude, strapdown

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

MODE_IDLE = 0       #: Mode::kIdle
MODE_NAVIGATE = 1   #: Mode::kNavigate

DEFAULT_TICK_HZ = 100          #: kDefaultTickHz
MAX_TICK_HZ = 10000            #: kMaxTickHz
MAX_LAT_RAD = 89.9 * np.pi / 180.0   #: kMaxLatRad

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
    }


def _finite3(v):
    return all(math.isfinite(x) for x in v)


def config_check(cfg):
    """PYINS_OK or the first PYINS_E_CONFIG_* that applies (mirrors config_check)."""
    if cfg["tick_hz"] < 0 or cfg["tick_hz"] > MAX_TICK_HZ:
        return PYINS_E_CONFIG_RATE
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
    return PYINS_OK


def wrap_two_pi(a):
    """Angle in [0, 2 pi)."""
    if 0.0 <= a < TWO_PI:
        return a
    w = a - TWO_PI * math.floor(a / TWO_PI)
    if w >= TWO_PI:
        w = 0.0
    return w


def wrap_pi(a):
    """Angle in (-pi, pi] for an input within (-3 pi, 3 pi]."""
    if a > np.pi:
        return a - TWO_PI
    if a <= -np.pi:
        return a + TWO_PI
    return a


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

    def init(self, cfg):
        hz = DEFAULT_TICK_HZ if cfg["tick_hz"] == 0 else cfg["tick_hz"]
        self.dt = 1.0 / float(hz)
        self.mode = MODE_NAVIGATE
        self.tick = 0
        self.table_angle = cfg["table_angle_rad"]
        self.encoder = wrap_two_pi(cfg["table_angle_rad"])
        self.enc_sin_half = math.sin(0.5 * self.encoder)
        self.enc_cos_half = math.cos(0.5 * self.encoder)
        euler_b = np.array(cfg["euler_b_rad"], dtype=float)
        mat_np = attitude.euler_to_mat(euler_b) @ attitude.rot_z(self.encoder)
        lon = cfg["lon_rad"]
        if lon > np.pi or lon <= -np.pi:
            lon = wrap_pi(wrap_two_pi(lon))
        nav = strapdown.NavState(cfg["lat_rad"], lon, cfg["height_m"],
                                 np.array(cfg["vel_n_mps"], dtype=float),
                                 attitude.mat_to_quat(mat_np))
        self.sd = strapdown.make_strapdown(nav, cfg["vertical_mode"])

    def step(self, dtheta_p, dv_p, table_angle_rad):
        """One tick; returns ``(status, output dict)``."""
        if not (_finite3(dtheta_p) and _finite3(dv_p) and math.isfinite(table_angle_rad)):
            return PYINS_E_SAMPLE_NONFINITE, self.output()
        strapdown.update(self.sd, np.asarray(dtheta_p, dtype=float),
                         np.asarray(dv_p, dtype=float), self.dt)
        encoder = wrap_two_pi(table_angle_rad)
        self.table_angle = self.table_angle + wrap_pi(encoder - self.encoder)
        if encoder != self.encoder:   # the table moved: refresh the cached half-angle
            self.encoder = encoder
            self.enc_sin_half = math.sin(0.5 * self.encoder)
            self.enc_cos_half = math.cos(0.5 * self.encoder)
        self.tick = self.tick + 1
        return PYINS_OK, self.output()

    def output(self):
        nav = self.sd.nav
        q_pb = np.array([self.enc_cos_half, 0.0, 0.0, -self.enc_sin_half])
        q_nb = attitude.quat_normalize(attitude.quat_mul(nav.quat_np, q_pb))
        euler_b = attitude.quat_to_euler(q_nb)
        return {
            "tick": self.tick,
            "mode": self.mode,
            "fault_flags": 0,
            "lat_rad": nav.lat,
            "lon_rad": nav.lon,
            "height_m": nav.height,
            "vel_n_mps": nav.vel_n.copy(),
            "quat_nb": q_nb,
            "quat_np": nav.quat_np.copy(),
            "euler_b_rad": euler_b,
            "heading_b_rad": attitude.yaw_to_heading(euler_b[2]),
            "yaw_p_rad": wrap_pi(euler_b[2] + self.encoder),
            "table_angle_rad": self.table_angle,
        }

    def run(self, dtheta_p, dv_p, table_angle_rad):
        """Step through arrays; returns a list of output dicts (stops at a rejected sample)."""
        outs = []
        for k in range(len(dtheta_p)):
            status, out = self.step(dtheta_p[k], dv_p[k], table_angle_rad[k])
            if status != PYINS_OK:
                raise ValueError(f"sample {k} rejected with status {status}")
            outs.append(out)
        return outs
