"""The turntable and the closed loop, in NumPy: the readable mirror of the
compiled plant ``csrc/plant/plant.cpp`` (pyins_plant.h), same per-tick order
of operations, used to cross-check it (and far too slow for long runs).
"""
from dataclasses import dataclass, field

import numpy as np

TABLE_OK, TABLE_STALL, TABLE_REVERSE, TABLE_JUMP = 0, 1, 2, 3
TWO_PI = 2.0 * np.pi


@dataclass
class TableConfig:
    """Motor and encoder of the turntable (pyins_table_config)."""
    rate_max_rad_s: float = 30.0 * np.pi / 180.0
    accel_max_rad_s2: float = 100.0 * np.pi / 180.0
    encoder_lsb_rad: float = 0.0
    jump_rad: float = 0.0
    fault_tick: int = 0
    fault: int = TABLE_OK


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
    """M x + bias dt (+ noise), quantised with the residual carried."""
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


def wrap_two_pi(a):
    w = a - TWO_PI * np.floor(a / TWO_PI)
    return 0.0 if w >= TWO_PI else w


def plant_tick(cfg, st, errors, omega_b, force_b, x, w, gyro_noise, accel_noise, dt):
    """One tick of the plant: returns (dtheta_p, dv_p, encoder, seq) for the
    firmware, advancing st; seq is the IMU's packet counter, the number of the
    tick the sample ends modulo 2^32 (as plant.cpp fills pyins_sample.seq).
    omega_b, force_b: (nodes, 3) ship rates."""
    half = 0.5 * dt
    a = table_accel(cfg, st, dt)
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
    st.alpha_rad = st.alpha_rad + st.rate_rad_s * dt + 0.5 * a * dt * dt
    st.rate_rad_s = st.rate_rad_s + a * dt
    st.tick = st.tick + 1
    gyro = apply_errors(errors["gyro_m"], errors["gyro_bias"], errors["gyro_quantum"], gyro_noise, dt,
                        st.gyro_residual, dtheta)
    accel = apply_errors(errors["accel_m"], errors["accel_bias"], errors["accel_quantum"], accel_noise, dt,
                         st.accel_residual, dv)
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
