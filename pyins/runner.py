"""Open-loop runs: simulated IMU data through the C++ firmware, against the truth.

``navigate`` generates the samples of a motion profile chunk by chunk (memory
stays bounded for any duration), steps them through ``pyins.native.Firmware``
keeping one record every ``every`` ticks, and returns those records beside
the true state at the same ticks; ``nav_errors`` turns the pair into errors
in physical units. The closed loop with the turntable (firmware-in-the-loop)
comes with the indexing issue.
"""
from dataclasses import dataclass

import numpy as np

from pyins import native, sim
from pyins.reference import attitude, earth


@dataclass
class RunResult:
    outputs: np.ndarray      #: OUTPUT_DTYPE records at the kept ticks
    truth: sim.Truth         #: true state at the same ticks
    dt: float


@dataclass
class NavErrors:
    """Errors of the firmware against the truth at each kept tick."""
    time_s: np.ndarray       #: ship time [s]
    north_m: np.ndarray      #: position error, north [m]
    east_m: np.ndarray       #: position error, east [m]
    horizontal_m: np.ndarray  #: horizontal position error [m]
    vel_n_mps: np.ndarray    #: velocity error, ENU (N, 3) [m/s]
    att_n_rad: np.ndarray    #: attitude error phi in n (E, N, U) (N, 3) [rad]:
    #:                          C_b^n(computed) = (I - phi x) C_b^n(true)


def initial_config(motion, table=None, **overrides):
    """Firmware configuration holding the true state of ``motion`` at t = 0.

    The state is the ship's reference point's (`pyins.sim.ShipAtSea`'s
    ``reference_state``), which is what the firmware's configuration and
    records mean when a lever arm is configured; ``lever_b_m``/``lever_p_m``
    come from the motion's lever arms unless overridden.
    """
    if hasattr(motion, "reference_state"):
        st = motion.reference_state(np.array([0.0]))
        overrides = {"lever_b_m": np.asarray(motion.lever_b, dtype=float),
                     "lever_p_m": np.asarray(motion.lever_p, dtype=float), **overrides}
    else:
        st = motion.state(np.array([0.0]))
    alpha0 = 0.0 if table is None else float(table.state(np.array([0.0]))[0][0])
    cfg = dict(lat_rad=float(st.lat[0]), lon_rad=float(st.lon[0]), height_m=float(st.height[0]),
               vel_n_mps=st.vel_n[0], euler_b_rad=st.euler[0], table_angle_rad=alpha0)
    cfg.update(overrides)
    return cfg


def navigate(motion, duration_ticks, every=100, sensors=None, table=None, config=None,
             chunk_ticks=100_000, dt=0.01, progress=None):
    """Run ``duration_ticks`` of ``motion`` through the C++ firmware.

    ``sensors`` is a ``pyins.sim.SensorModel`` (None: error-free), ``table`` a
    turntable profile, ``config`` overrides of the firmware configuration
    (default: the true initial state). Returns a RunResult with one record
    and one truth row every ``every`` ticks.
    """
    cfg = initial_config(motion, table, **(config or {}))
    fw = native.Firmware(cfg)
    outs = []
    for chunk in sim.generate(motion, duration_ticks, chunk_ticks=chunk_ticks, dt=dt, table=table,
                              sensors=sensors, with_truth=False):
        # seq: the tick number each sample ends, as an IMU's packet counter
        # (read only when the configuration sets seq_mode = 1)
        samples = native.make_samples(chunk.dtheta_p, chunk.dv_p, chunk.table_angle, seq=chunk.tick)
        rec = fw.run(samples, every=every)
        outs.append(rec)
        if progress is not None:
            progress(int(chunk.tick[-1]), duration_ticks)
    outputs = np.concatenate(outs) if outs else np.zeros(0, dtype=native.OUTPUT_DTYPE)
    ticks = outputs["tick"]
    truth = sim.truth_at(motion, ticks, dt=dt, table=table)
    return RunResult(outputs=outputs, truth=truth, dt=dt)


def nav_errors(result):
    """Position, velocity and attitude errors of a RunResult."""
    out, tr = result.outputs, result.truth
    lat_t = tr.lat
    rm, rn = earth.principal_radii(np.sin(lat_t))
    north = (out["lat_rad"] - lat_t) * (rm + tr.height)
    dlon = np.mod(out["lon_rad"] - tr.lon + np.pi, 2 * np.pi) - np.pi
    east = dlon * (rn + tr.height) * np.cos(lat_t)
    att = np.empty((len(out), 3))
    for k in range(len(out)):
        # q_err = q_nb(computed) (x) conj(q_nb(true)) = rotation by -phi in n
        q_err = attitude.quat_mul(out["quat_nb"][k], attitude.quat_conj(tr.quat_nb[k]))
        att[k] = -attitude.quat_to_rotvec(attitude.quat_normalize(q_err))
    return NavErrors(time_s=out["tick"] * result.dt, north_m=north, east_m=east,
                     horizontal_m=np.hypot(north, east), vel_n_mps=out["vel_n_mps"] - tr.vel_n,
                     att_n_rad=att)
