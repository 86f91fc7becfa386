#!/usr/bin/env python3
"""Peer side of tools/bench_peer_gnss.py: nmayorov/pyins's (PyPI
``python-ins``) feedback filter on a voyage the project simulated.

Runs INSIDE the peer virtual environment (.venv-peer; both packages import
as ``pyins``), never in the project's venv. Nothing of nmayorov/pyins is
copied here: this script only calls the installed package.

    .venv-peer/bin/python -I tools/peer_gnss_filter.py DIR

DIR holds what tools/bench_peer_gnss.py wrote: ``dtheta.npy``, ``dv.npy``
(n x 3, the 100 Hz increments in the project's body frame b = starboard,
bow, up), ``gnss_pos.npy`` (m x 4: tick, lat rad, lon rad, height m),
``gnss_vel.npy`` (m x 4: tick, east, north, up m/s) and ``meta.json``
(``dt_s``, the initial state ``lat_rad``, ``lon_rad``, ``height_m``,
``vel_enu``, ``C_bn`` (b to ENU), and the filter's settings: the initial
sigmas, the sensor models' bias sigmas and noise densities, the
measurement sigmas, ``time_step``). The frames are turned into the peer's
(b -> forward-right-down, ENU -> NED: one fixed proper rotation M, C_peer =
M C_bn M) before the clock starts. Writes ``peer.npz``: the peer's
trajectory at the GNSS ticks (``tick``, ``lat_rad``, ``lon_rad``,
``heading_rad`` clockwise from north) and ``elapsed_s`` (run_feedback_filter
alone).
"""
import json
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pyins import filters, inertial_sensor, measurements, transform  # the peer's package

#: b (starboard, bow, up) <-> FRD and ENU <-> NED: the same symmetric swap
M = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])


def main(d):
    d = Path(d)
    meta = json.loads((d / "meta.json").read_text())
    dt = meta["dt_s"]
    th = np.load(d / "dtheta.npy") @ M.T          # FRD = M b
    dv = np.load(d / "dv.npy") @ M.T
    n = len(th)
    t = np.arange(1, n + 1) * dt
    increments = pd.DataFrame(data=np.column_stack([np.full(n, dt), th, dv]), index=t,
                              columns=["dt", "theta_x", "theta_y", "theta_z", "dv_x", "dv_y", "dv_z"])
    c_peer = M @ np.array(meta["C_bn"]) @ M
    rph = transform.mat_to_rph(c_peer)
    ve, vn, vu = meta["vel_enu"]
    pva = pd.Series({"lat": np.degrees(meta["lat_rad"]), "lon": np.degrees(meta["lon_rad"]),
                     "alt": meta["height_m"], "VN": vn, "VE": ve, "VD": -vu,
                     "roll": rph[0], "pitch": rph[1], "heading": rph[2]}, name=0.0)   # at t = 0
    pos = np.load(d / "gnss_pos.npy")
    vel = np.load(d / "gnss_vel.npy")
    pos_df = pd.DataFrame({"lat": np.degrees(pos[:, 1]), "lon": np.degrees(pos[:, 2]), "alt": pos[:, 3]},
                          index=pos[:, 0] * dt)
    vel_df = pd.DataFrame({"VN": vel[:, 2], "VE": vel[:, 1], "VD": -vel[:, 3]}, index=vel[:, 0] * dt)
    s = meta["filter"]
    gyro = inertial_sensor.EstimationModel(bias_sd=s["gyro_bias_sd"], noise=s["gyro_noise"])
    accel = inertial_sensor.EstimationModel(bias_sd=s["accel_bias_sd"], noise=s["accel_noise"])
    meas = [measurements.Position(pos_df, s["pos_sd"]), measurements.NedVelocity(vel_df, s["vel_sd"])]
    t0 = time.perf_counter()
    res = filters.run_feedback_filter(pva, s["position_sd"], s["velocity_sd"], s["level_sd_deg"],
                                      s["azimuth_sd_deg"], increments, gyro_model=gyro, accel_model=accel,
                                      measurements=meas, time_step=s["time_step"],
                                      with_altitude=s["with_altitude"])
    elapsed = time.perf_counter() - t0
    tr = res.trajectory
    at = pos[:, 0] * dt
    tr = tr.loc[tr.index.intersection(at)]
    np.savez(d / "peer.npz", tick=np.rint(np.asarray(tr.index) / dt).astype(np.int64),
             lat_rad=np.radians(tr["lat"].to_numpy()), lon_rad=np.radians(tr["lon"].to_numpy()),
             heading_rad=np.radians(tr["heading"].to_numpy()), elapsed_s=elapsed)
    print(json.dumps({"elapsed_s": elapsed, "rows": len(tr)}))


if __name__ == "__main__":
    main(sys.argv[1])
