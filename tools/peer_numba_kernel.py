#!/usr/bin/env python3
"""Peer timing server: nmayorov/pyins (PyPI `python-ins`) strapdown integration.

Runs INSIDE the peer virtual environment (.venv-peer, made by
tools/bench_strapdown.py --peer numba), never in the project's own venv: both
packages import as ``pyins``. Nothing of nmayorov/pyins is copied here; this
script only calls the installed package.

    .venv-peer/bin/python -I tools/peer_numba_kernel.py DIR
    .venv-peer/bin/python -I tools/peer_numba_kernel.py --count DIR N

(--count: integrate the first N increments once with the kernel, JIT compile
included, and exit; tools/bench_strapdown.py --peer-callgrind runs this under
valgrind for two N and differences the totals.)

DIR holds what tools/bench_strapdown.py wrote: ``dtheta.npy`` and ``dv.npy``
(n x 3 float64, angle [rad] and velocity [m/s] increments per 100 Hz tick in
the project's body frame b = starboard-bow-up) and ``meta.json`` (``dt_s``,
``lat_rad``, ``lon_rad``, ``height_m``, ``C_bn``: the initial body-to-ENU
matrix, ``with_altitude``). The increments are turned into the peer's frames
(b -> forward-right-down, n -> NED: one fixed proper rotation, the same
matrix on both sides) before any timing, and put into the peer's
``Increments`` DataFrame (columns dt, theta_*, dv_*), the form
``pyins.strapdown.compute_increments_from_imu`` hands its users.

Protocol (one line in, one line out, on stdin/stdout):

    ready {json}        printed once after loading and warming the numba JIT
    run                 -> elapsed seconds of the numba kernel alone:
                           pyins._numba_integrate.integrate(dt, lla, velocity_n,
                           mat_nb, theta, dv, 0, with_altitude) over all n
                           increments, into output arrays allocated before the
                           clock starts (the kernel stores lla, velocity and the
                           3x3 attitude matrix of every step; it has no
                           "no output" mode)
    run_integrator      -> elapsed seconds of the users' path:
                           pyins.strapdown.Integrator(pva, with_altitude)
                           .integrate(increments) (array growth, the kernel,
                           mat_to_rph and the pandas Trajectory frame)
    quit                -> exits

Any failure is printed as ``error <message>`` and the script exits 1.
"""
import json
import sys
import time
from pathlib import Path

import numpy as np

# b (starboard, bow, up) -> forward-right-down, and ENU -> NED: the same
# symmetric, orthogonal, det +1 matrix (swap x and y, negate z).
M = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])


def reply(line):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def main(argv):
    count = None
    if len(argv) == 4 and argv[1] == "--count":
        count = int(argv[3])
        argv = argv[:1] + argv[2:3]
    if len(argv) != 2:
        reply("error usage: peer_numba_kernel.py [--count] DIR [N]")
        return 1
    import numba
    import pandas as pd
    import pyins as peer
    from importlib.metadata import version
    from pyins import strapdown, transform
    from pyins._numba_integrate import integrate

    src = Path(argv[1])
    meta = json.loads((src / "meta.json").read_text())
    theta = np.ascontiguousarray(np.load(src / "dtheta.npy") @ M)   # rows: M @ v (M symmetric)
    dv = np.ascontiguousarray(np.load(src / "dv.npy") @ M)
    n = theta.shape[0]
    dt_s = float(meta["dt_s"])
    with_altitude = bool(meta.get("with_altitude", False))
    c_nb = M @ np.asarray(meta["C_bn"]) @ M                         # FRD -> NED
    lat_deg = np.degrees(meta["lat_rad"])
    lon_deg = np.degrees(meta["lon_rad"])
    rph = transform.mat_to_rph(c_nb)

    dt = np.full(n, dt_s)
    time_s = dt_s * np.arange(1, n + 1)
    increments = pd.DataFrame(np.column_stack([dt, theta, dv]), index=time_s,
                              columns=["dt", "theta_x", "theta_y", "theta_z",
                                       "dv_x", "dv_y", "dv_z"])
    pva = pd.Series({"lat": lat_deg, "lon": lon_deg, "alt": float(meta["height_m"]),
                     "VN": 0.0, "VE": 0.0, "VD": 0.0,
                     "roll": rph[0], "pitch": rph[1], "heading": rph[2]}, name=0.0)

    lla = np.empty((n + 1, 3))
    vel = np.empty((n + 1, 3))
    mat = np.empty((n + 1, 3, 3))

    if count is not None:   # one kernel call on the first `count` increments (callgrind)
        lla[0] = (lat_deg, lon_deg, meta["height_m"])
        vel[0] = 0.0
        mat[0] = c_nb
        integrate(dt[:count], lla, vel, mat, theta[:count], dv[:count], 0, with_altitude)
        reply(f"done {count}")
        return 0

    def kernel():
        lla[0] = (lat_deg, lon_deg, meta["height_m"])
        vel[0] = 0.0
        mat[0] = c_nb
        t0 = time.perf_counter()
        integrate(dt, lla, vel, mat, theta, dv, 0, with_altitude)
        return time.perf_counter() - t0

    def integrator():
        t0 = time.perf_counter()
        traj = strapdown.Integrator(pva, with_altitude=with_altitude).integrate(increments)
        elapsed = time.perf_counter() - t0
        return elapsed, traj

    # warm the JIT (compile on first call), then one full run of each path
    integrate(dt[:10], lla, vel, mat, theta[:10], dv[:10], 0, with_altitude)
    kernel()
    _, traj = integrator()
    # sanity: the ship stays at its mean position; drift after n steps [m]
    r_e = 6378137.0
    dn = np.radians(lla[n, 0] - lat_deg) * r_e
    de = np.radians(lla[n, 1] - lon_deg) * r_e * np.cos(meta["lat_rad"])
    same = bool(np.allclose(traj[["lat", "lon"]].values[-1], lla[n, :2], rtol=0, atol=1e-12))
    reply("ready " + json.dumps({
        "python_ins_version": version("python-ins"), "numba_version": numba.__version__,
        "peer_module": peer.__file__, "steps": n, "with_altitude": with_altitude,
        "final_position_drift_m": float(np.hypot(dn, de)),
        "final_speed_mps": float(np.linalg.norm(vel[n])),
        "integrator_equals_kernel": same}))

    for line in sys.stdin:
        cmd = line.strip()
        if cmd == "run":
            reply(repr(kernel()))
        elif cmd == "run_integrator":
            reply(repr(integrator()[0]))
        elif cmd in ("quit", ""):
            break
        else:
            reply(f"error unknown command {cmd!r}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except Exception as exc:  # report, never hang the parent
        reply(f"error {type(exc).__name__}: {exc}")
        sys.exit(1)
