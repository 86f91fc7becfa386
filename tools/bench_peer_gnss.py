#!/usr/bin/env python3
"""An independent GNSS/INS filter side by side with the firmware's
integrated navigation filter, on the same simulated voyage with the same
GNSS, in one run (the at-sea issue's peer comparison).

    .venv/bin/python tools/bench_peer_gnss.py [--hours 1] [--seed 1]

The peer is nmayorov/pyins (PyPI ``python-ins`` 1.0.1): its feedback
filter (``pyins.filters.run_feedback_filter``, an error-state EKF with
position and NED-velocity measurements, no gating), run in its own virtual
environment .venv-peer (both packages import as ``pyins``; made on demand as
tools/bench_strapdown.py --peer numba makes it) by tools/peer_gnss_filter.py.

The data: `pyins.sim.default_voyage(hours, seed)` (a transit at 5-20 kn
with course and speed changes, the general sea state's swing and heave),
seed 002's sensor errors (seed 3), the IMU fixed to the ship (the peer has
no turntable), an initial attitude error of 1', -1', 5' (E, N, U), a 1 Hz
GNSS (3 m white, 5 m up, a 2 m Gauss-Markov bias over 300 s, 0.05 m/s;
seed 5). Both filters get the same increments (the 100 Hz samples the
firmware steps), the same fixes at the same times, the same sigmas (3.6 m:
sqrt(3^2 + 2^2), as the firmware is handed; 0.05 m/s) and the same priors
(the firmware's defaults: attitude 2', 2', 10'; gyro bias 0.01 deg/h,
accelerometer bias 100 ug, gyro noise 0.001 deg/sqrt(h), accelerometer
noise 10 ug/sqrt(Hz); velocity 0.1 m/s, position 10 m); both hold the
vertical channel. The peer's covariance steps every second (its
``time_step``; ours every second too).

Printed: horizontal error RMS after 10 min and its maximum, heading error
RMS after 20 min, and the wall time per hour of data of each (the peer's
run_feedback_filter alone; ours the firmware's run with its references,
compiled), with their ratio. Not a timed test: a benchmark that prints.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

from bench_strapdown import NotMeasured, ensure_peer_venv  # noqa: E402  (the peer venv, made on demand)

from pyins import aiding, contract, metrics, native, sim  # noqa: E402
from pyins.open_loop import RunResult  # noqa: E402
from pyins.reference import attitude, earth  # noqa: E402
from pyins.scenario.build import initial_config, initial_errors  # noqa: E402
from pyins.sim import references  # noqa: E402
from pyins.units import ARCMIN_TO_RAD, DEG_TO_RAD, DT, G0  # noqa: E402

PEER_SCRIPT = ROOT / "tools" / "peer_gnss_filter.py"
PHI0 = np.array([1.0, -1.0, 5.0]) * ARCMIN_TO_RAD
SIGMA0_ATT = np.array([2.0, 2.0, 10.0]) * ARCMIN_TO_RAD


def simulate(hours, seed):
    motion = sim.default_voyage(hours, seed=seed)
    n = int(round(hours * 3600.0 / DT))
    chunks = list(sim.generate(motion, n, chunk_ticks=200_000, dt=DT,
                               sensors=sim.SensorModel(sim.preset("seed002"), seed=3), with_truth=False))
    th = np.concatenate([c.dtheta_p for c in chunks])
    dv = np.concatenate([c.dv_p for c in chunks])
    alpha = np.concatenate([c.table_angle for c in chunks])
    g = references.gnss(motion, n * DT, seed=5)
    return motion, th, dv, alpha, g


def run_ours(motion, th, dv, alpha, g):
    cfg = initial_config(motion, None, **initial_errors(motion, phi=PHI0), fine_sigma0_att_rad=SIGMA0_ATT)
    fw = native.Firmware(cfg)
    samples = contract.make_samples(th, dv, alpha)
    t0 = time.perf_counter()
    out = aiding.Aider(g.refs.astype(contract.REF_DTYPE), g.avail_tick).run(fw, samples, every=100)
    elapsed = time.perf_counter() - t0
    return out, elapsed


def run_peer(motion, th, dv, g, workdir):
    py = ensure_peer_venv()
    cfg = initial_config(motion, None, **initial_errors(motion, phi=PHI0))
    refs = g.refs
    pos, vel = refs[refs["kind"] == 1], refs[refs["kind"] == 2]
    np.save(workdir / "dtheta.npy", th)
    np.save(workdir / "dv.npy", dv)
    np.save(workdir / "gnss_pos.npy", np.column_stack([pos["tick"], pos["value"]]))
    np.save(workdir / "gnss_vel.npy", np.column_stack([vel["tick"], vel["value"]]))
    meta = dict(dt_s=DT, lat_rad=cfg["lat_rad"], lon_rad=cfg["lon_rad"], height_m=cfg["height_m"],
                vel_enu=list(map(float, cfg["vel_n_mps"])),
                C_bn=attitude.euler_to_mat(np.asarray(cfg["euler_b_rad"])).tolist(),
                filter=dict(position_sd=10.0, velocity_sd=0.1, level_sd_deg=2.0 / 60.0,
                            azimuth_sd_deg=10.0 / 60.0,
                            gyro_bias_sd=0.01 * DEG_TO_RAD / 3600.0, gyro_noise=0.001 * DEG_TO_RAD / 60.0,
                            accel_bias_sd=100e-6 * G0, accel_noise=10e-6 * G0,
                            pos_sd=float(pos["sigma"][0, 0]), vel_sd=float(vel["sigma"][0, 0]),
                            time_step=1.0, with_altitude=False))
    (workdir / "meta.json").write_text(json.dumps(meta))
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    env["NUMBA_NUM_THREADS"] = "1"
    res = subprocess.run([str(py), "-I", str(PEER_SCRIPT), str(workdir)], capture_output=True, text=True,
                         env=env, cwd=str(workdir), timeout=3600)
    if res.returncode != 0:
        raise NotMeasured(f"the peer's filter failed: {res.stderr.strip()[-400:]}")
    with np.load(workdir / "peer.npz") as z:
        return {k: z[k] for k in z.files}


def errors_at(motion, ticks, lat, lon, heading):
    truth = sim.truth_at(motion, ticks, dt=DT)
    rm, rn = earth.principal_radii(np.sin(truth.lat))
    north = (lat - truth.lat) * (rm + truth.height)
    east = (lon - truth.lon) * (rn + truth.height) * np.cos(truth.lat)
    true_heading = np.mod(-truth.euler[:, 2], 2.0 * np.pi)
    dh = np.angle(np.exp(1j * (heading - true_heading)))
    return ticks * DT, np.hypot(north, east), dh


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=1, help="the voyage's route seed")
    args = ap.parse_args()
    print(f"voyage {args.hours:g} h (route seed {args.seed}), seed 002's sensor errors, IMU fixed, "
          "GNSS 1 Hz (3 m, 2 m Gauss-Markov bias, 0.05 m/s)", flush=True)
    motion, th, dv, alpha, g = simulate(args.hours, args.seed)
    out, t_ours = run_ours(motion, th, dv, alpha, g)
    e = metrics.nav_errors(RunResult(outputs=out, truth=sim.truth_at(motion, out["tick"], dt=DT), dt=DT))
    rows = {"pyins firmware (C++)": (e.time_s, e.horizontal_m, e.att_n_rad[:, 2], t_ours)}
    with tempfile.TemporaryDirectory(prefix="pyins-peer-gnss-") as tmp:
        try:
            p = run_peer(motion, th, dv, g, Path(tmp))
            # heading error = firmware heading - true (clockwise): phi_U = -(that)
            t, hor, dh = errors_at(motion, p["tick"], p["lat_rad"], p["lon_rad"], p["heading_rad"])
            rows["nmayorov/pyins 1.0.1 feedback filter"] = (t, hor, -dh, float(p["elapsed_s"]))
        except NotMeasured as exc:
            print(f"peer: not measured: {exc}")
    hours = args.hours
    print(f"{'filter':40s} {'horiz RMS >10 min':>18s} {'horiz max >10 min':>18s} "
          f"{'heading RMS >20 min':>20s} {'s per hour of data':>19s}")
    for name, (t, hor, head, wall) in rows.items():
        late, later = t >= 600.0, t >= 1200.0
        print(f"{name:40s} {np.sqrt(np.mean(hor[late] ** 2)):16.2f} m {hor[late].max():16.2f} m "
              f"{np.sqrt(np.mean(head[later] ** 2)) / ARCMIN_TO_RAD:18.3f}' {wall / hours:19.3f}")
    if len(rows) == 2:
        (_, (_, _, _, a)), (_, (_, _, _, b)) = rows.items()
        print(f"time ratio peer / firmware: {b / a:.1f}x (the firmware's time includes pushing each fix "
              "through the C ABI; the peer's is run_feedback_filter alone)")


if __name__ == "__main__":
    main()
