"""The turntable: its motion profiles for the open-loop simulator, and the
closed loop in NumPy, the readable mirror of the compiled plant
``csrc/plant/plant.cpp`` (pyins_plant.h).

The table angle alpha turns the IMU frame p against the body frame b,
C_p^b = Rz(alpha), counter-clockwise seen from above (docs/design.md §2);
the encoder reads alpha at the end of each tick (docs/design.md §3).

1. Open-loop profiles, ``state(t, t_lo=None) -> (alpha, alpha_dot)``, that
   `pyins.sim.imu` turns the ship's rates with: `TableMotion`, `Fixed`,
   `ConstantRate`.
2. The plant mirror, per tick in the order of ``pyins_fil_run``: the
   motor's acceleration (`table_accel`), the increments of the turning IMU,
   the table advanced, the sensor errors (`apply_errors`), the encoder
   (`wrap_two_pi`); `plant_tick` is one tick. Same names and arithmetic as
   plant.cpp, so the two agree bit for bit (tests/crosscheck); far too
   slow for long runs.
"""
from dataclasses import dataclass, field

import numpy as np

from pyins.reference.angle import wrap_two_pi  # the core's, which plant.cpp wraps with
from pyins.sim.exact_time import as_times, frac_cycles
from pyins.units import DEG_TO_RAD, TWO_PI


# ---------------------------------------------------------------------------
# 1. Open-loop profiles
# ---------------------------------------------------------------------------
class TableMotion:
    """Base class of turntable profiles: ``state(t, t_lo=None) -> (alpha, alpha_dot)``.

    alpha is the table angle [rad] (C_p^b = Rz(alpha), counter-clockwise seen
    from above), alpha_dot its rate [rad/s]. alpha may be returned reduced by
    whole turns; callers wrap it. ``state3`` adds the exact angular
    acceleration [rad/s^2], needed when the accelerometer triad sits off the
    table axis (``lever_p`` of `pyins.sim.ship.ShipAtSea`). Times are exact
    pairs ``t + t_lo`` (`pyins.sim.exact_time`).
    """

    def state(self, t, t_lo=None):
        raise NotImplementedError

    def state3(self, t, t_lo=None):
        """``(alpha, alpha_dot, alpha_ddot)`` at the times, each (N,)."""
        raise NotImplementedError(f"{type(self).__name__} gives no angular acceleration "
                                  f"(state3), which a rotating lever_p needs")


class Fixed(TableMotion):
    """Turntable held at ``alpha0`` [rad]."""

    def __init__(self, alpha0=0.0):
        self.alpha0 = float(alpha0)

    def state(self, t, t_lo=None):
        t, _ = as_times(t, t_lo)
        return np.full(t.shape, self.alpha0), np.zeros(t.shape)

    def state3(self, t, t_lo=None):
        alpha, rate = self.state(t, t_lo)
        return alpha, rate, np.zeros(alpha.shape)


class ConstantRate(TableMotion):
    """Turntable turning at a constant ``rate`` [rad/s] from ``alpha0`` [rad].

    alpha(t) = alpha0 + rate t, with whole turns removed exactly (the turn
    count rate t / (2 pi) is reduced with `frac_cycles`).
    """

    def __init__(self, rate, alpha0=0.0):
        self.rate = float(rate)
        self.alpha0 = float(alpha0)
        self._cycles_per_s = self.rate / TWO_PI

    def state(self, t, t_lo=None):
        t, t_lo = as_times(t, t_lo)
        alpha = self.alpha0 + TWO_PI * frac_cycles(self._cycles_per_s, t, t_lo)
        return alpha, np.full(t.shape, self.rate)

    def state3(self, t, t_lo=None):
        alpha, rate = self.state(t, t_lo)
        return alpha, rate, np.zeros(alpha.shape)


# ---------------------------------------------------------------------------
# 2. The plant mirror (csrc/plant/plant.cpp)
# ---------------------------------------------------------------------------
TABLE_OK, TABLE_STALL, TABLE_REVERSE, TABLE_JUMP = 0, 1, 2, 3   #: enum pyins_table_fault


@dataclass
class TableConfig:
    """Motor and encoder of the turntable (pyins_table_config)."""
    rate_max_rad_s: float = 30.0 * DEG_TO_RAD       #: motor rate limit [rad/s]
    accel_max_rad_s2: float = 100.0 * DEG_TO_RAD    #: motor acceleration limit [rad/s^2]
    encoder_lsb_rad: float = 0.0                    #: encoder step [rad]; 0 = none
    jump_rad: float = 0.0                           #: encoder jump of the JUMP fault [rad]
    fault_tick: int = 0                             #: tick from which the fault acts
    fault: int = TABLE_OK                           #: TABLE_OK, _STALL, _REVERSE or _JUMP


@dataclass
class PlantState:
    """pyins_plant_state."""
    tick: int = 0
    alpha_rad: float = 0.0
    rate_rad_s: float = 0.0
    rate_cmd_rad_s: float = 0.0
    gyro_residual: np.ndarray = field(default_factory=lambda: np.zeros(3))
    accel_residual: np.ndarray = field(default_factory=lambda: np.zeros(3))


def table_accel(cfg, st, dt):
    """Acceleration over one tick: reach the command within the tick if the
    motor's limits allow (mirrors table_accel)."""
    cmd = st.rate_cmd_rad_s
    active = cfg.fault != TABLE_OK and st.tick >= cfg.fault_tick
    if active and cfg.fault == TABLE_STALL:
        cmd = 0.0
    elif active and cfg.fault == TABLE_REVERSE:
        cmd = -cmd
    cmd = min(max(cmd, -cfg.rate_max_rad_s), cfg.rate_max_rad_s)
    a = (cmd - st.rate_rad_s) / dt
    return min(max(a, -cfg.accel_max_rad_s2), cfg.accel_max_rad_s2)


def apply_errors(m, bias, quantum, noise, dt, res, x):
    """M x + bias dt (+ noise), quantised with the residual carried
    (mirrors apply_errors; the model of `pyins.sim.sensors`)."""
    out = np.empty(3)
    for i in range(3):
        v = m[i, 0] * x[0] + m[i, 1] * x[1] + m[i, 2] * x[2] + bias[i] * dt
        if noise is not None:
            v = v + noise[i]
        if quantum > 0.0:
            total = v + res[i]
            q = quantum * np.rint(total / quantum)
            res[i] = total - q
            v = q
        out[i] = v
    return out


def plant_tick(cfg, st, errors, omega_b, force_b, x, w, gyro_noise, accel_noise, dt):
    """One tick of the plant: returns (dtheta_p, dv_p, encoder, seq) for the
    firmware, advancing st; seq is the IMU's packet counter, the number of the
    tick the sample ends modulo 2^32 (as plant.cpp fills pyins_sample.seq).
    omega_b, force_b: (nodes, 3) ship rates; x, w: the Gauss-Legendre nodes
    on [-1, 1] and weights."""
    half = 0.5 * dt
    # 1. The motor's acceleration over the tick (constant within it).
    a = table_accel(cfg, st, dt)
    # 2. The increments: omega_ip^p = Rz(alpha)^T omega_ib^b + alpha_dot z,
    #    f^p = Rz(alpha)^T f^b, integrated over the tick by Gauss-Legendre
    #    (at rest, one alpha: Rz^T once on the weighted sums).
    if st.rate_rad_s == 0.0 and a == 0.0:
        # a table at rest all tick: Rz^T once on the weighted node sums
        c, s = np.cos(st.alpha_rad), np.sin(st.alpha_rad)
        w_sum = np.zeros(3)
        f_sum = np.zeros(3)
        for j in range(len(x)):
            w_sum = w_sum + w[j] * omega_b[j]
            f_sum = f_sum + w[j] * force_b[j]
        dtheta = np.array([c * w_sum[0] + s * w_sum[1], -s * w_sum[0] + c * w_sum[1], w_sum[2]])
        dv = np.array([c * f_sum[0] + s * f_sum[1], -s * f_sum[0] + c * f_sum[1], f_sum[2]])
    else:
        dtheta = np.zeros(3)
        dv = np.zeros(3)
        for j in range(len(x)):
            tau = 0.5 * (1.0 + x[j]) * dt
            alpha = st.alpha_rad + st.rate_rad_s * tau + 0.5 * a * tau * tau
            alpha_dot = st.rate_rad_s + a * tau
            c, s = np.cos(alpha), np.sin(alpha)
            wb, fb = omega_b[j], force_b[j]
            dtheta = dtheta + w[j] * np.array([c * wb[0] + s * wb[1], -s * wb[0] + c * wb[1],
                                               wb[2] + alpha_dot])
            dv = dv + w[j] * np.array([c * fb[0] + s * fb[1], -s * fb[0] + c * fb[1], fb[2]])
    dtheta = half * dtheta
    dv = half * dv
    # 3. The table at the end of the tick.
    st.alpha_rad = st.alpha_rad + st.rate_rad_s * dt + 0.5 * a * dt * dt
    st.rate_rad_s = st.rate_rad_s + a * dt
    st.tick = st.tick + 1
    # 4. The sensor errors.
    gyro = apply_errors(errors["gyro_m"], errors["gyro_bias"], errors["gyro_quantum"], gyro_noise, dt,
                        st.gyro_residual, dtheta)
    accel = apply_errors(errors["accel_m"], errors["accel_bias"], errors["accel_quantum"], accel_noise, dt,
                         st.accel_residual, dv)
    # 5. The encoder: the JUMP fault, the wrap, the quantisation.
    enc = st.alpha_rad
    if cfg.fault == TABLE_JUMP and st.tick > cfg.fault_tick:
        enc = enc + cfg.jump_rad
    enc = wrap_two_pi(enc)
    if cfg.encoder_lsb_rad > 0.0:
        enc = cfg.encoder_lsb_rad * np.floor(enc / cfg.encoder_lsb_rad)
    return gyro, accel, enc, st.tick & 0xFFFFFFFF


def error_matrices(sensor_errors):
    """The plant's view of pyins.sim.SensorErrors: M = I + diag(scale) + mis."""
    e = sensor_errors
    return {
        "gyro_m": np.eye(3) + np.diag(e.gyro_scale) + e.gyro_misalignment,
        "gyro_bias": np.asarray(e.gyro_bias, dtype=float),
        "gyro_quantum": float(e.gyro_quantum),
        "accel_m": np.eye(3) + np.diag(e.accel_scale) + e.accel_misalignment,
        "accel_bias": np.asarray(e.accel_bias, dtype=float),
        "accel_quantum": float(e.accel_quantum),
    }
