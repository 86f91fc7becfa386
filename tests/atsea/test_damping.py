"""Level damping by the EM speed log (docs/concepts.md, "At sea"): the
log's speed through water along the bow, with the current learnt from the
first minute of readings, drives a third-order damping network on each
horizontal channel while it is the only reference in use and the course is
straight; the record says DAMPED (the position is dead reckoning).

The voyage: `pyins.sim.default_voyage(4 h, seed=1)` (15.5 -> 11.5 kn,
course changes, the general sea state's swing and heave) drifting with a
water current of 0.2 m/s (0.12 E, 0.16 N) and a tidal ellipse of 0.05 m/s
at the M2 period (`pyins.sim.references.Current`: the ship crabs, its
water velocity along its bow), seed 002's sensor errors, the IMU fixed,
started with 0.5', -0.5', 3' of attitude error; a 1 Hz log with 0.05 m/s
noise and a 0.5 % scale factor, told 0.1 m/s. Measured on the landed code
(2026-12-05):

    unaided:  the north velocity error's Schuler oscillation 0.97 m/s
              (84-min band of its spectrum), 4.4 km after 4 h
    damped:   0.064 m/s in the same band (15x smaller), 791 m after 4 h:
              the log's scale factor (0.5 % of 8-10 m/s along the track),
              the tide's change since the current was learnt, and the
              INS's own velocity error of that first minute, which the
              learnt current absorbed (the 0.5' tilt: ~0.04 m/s)
    switches: 11 between UNDAMPED (turns, the first 70 s) and DAMPED; the
              velocity error moves by at most 1.09 mm/s across one, the
              position error by 0.46 m in that second (its rate then)
"""
import engines
import numpy as np
import pytest

from pyins import contract, metrics, sim
from pyins.open_loop import navigate
from pyins.reference import abi
from pyins.scenario.build import initial_errors
from pyins.sim import references
from pyins.units import ARCMIN_TO_RAD, DT

HOURS = 4.0
SCHULER_HZ = 1.0 / 5064.0           # the 84.4-min Schuler period


CURRENT = references.Current(mean_enu=(0.12, 0.16), amplitude_mps=0.05, seed=1)


@pytest.fixture(scope="module")
def motion():
    return sim.default_voyage(HOURS, seed=1, current=CURRENT)


def _log(motion, seconds):
    lg = references.speed_log(motion, seconds, CURRENT, rate_hz=1.0, scale_factor=0.005,
                              noise_mps=0.05, seed=3)
    refs = lg.refs.astype(contract.REF_DTYPE)
    refs["sigma"][:, 0] = 0.1        # noise and scale factor: the sigma the log is told
    return refs


def _run(motion, n, refs, engine="native", every=100):
    cfg = dict(initial_errors(motion, phi=np.array([0.5, -0.5, 3.0]) * ARCMIN_TO_RAD),
               fine_sigma0_att_rad=np.array([1.0, 1.0, 10.0]) * ARCMIN_TO_RAD)
    res = navigate(motion, n, every=every, sensors=sim.SensorModel(sim.preset("seed002"), seed=3), config=cfg,
                   refs=refs, engine=engine)
    return metrics.nav_errors(res), res.outputs


def _schuler_amplitude(v):
    """Largest spectral amplitude of ``v`` (one record a second) within
    0.6-1.6 x the Schuler frequency."""
    x = v - v.mean()
    f = np.fft.rfftfreq(len(x), 1.0)
    a = np.abs(np.fft.rfft(x)) * 2.0 / len(x)
    return a[(f > 0.6 * SCHULER_HZ) & (f < 1.6 * SCHULER_HZ)].max()


@pytest.fixture(scope="module")
def runs(motion):
    n = int(HOURS * 3600 / DT)
    return _run(motion, n, None), _run(motion, n, _log(motion, n * DT))


def test_the_log_damps_the_schuler_oscillation(runs):
    (ef, of), (ed, od) = runs
    free, damped = _schuler_amplitude(ef.vel_n_mps[:, 1]), _schuler_amplitude(ed.vel_n_mps[:, 1])
    print(f"\nSchuler band of the north velocity error: unaided {free:.3f} m/s, damped {damped:.3f} m/s "
          f"({free / damped:.0f}x); horizontal after {HOURS:g} h: {ef.horizontal_m[-1]:.0f} m unaided, "
          f"{ed.horizontal_m[-1]:.0f} m damped")
    # the at-sea acceptance: at least 10x smaller (measured 14x)
    assert damped * 10.0 <= free
    # the position error is dead reckoning's: 0.5 % of the speed (8-10 m/s)
    # along the track over 4 h is up to ~700 m, the tide's change and the
    # learnt current's error a few hundred more; 1.5 km leaves room and still
    # fails an undamped run (4.4 km)
    assert ed.horizontal_m[-1] < 1500.0 < ef.horizontal_m[-1]
    # DAMPED on the straight legs, UNDAMPED in the turns (and the first 70 s:
    # the current's mean and 10 s of straight course)
    modes = set(np.unique(od["nav_mode"]).tolist())
    assert modes == {abi.PYINS_NAV_UNDAMPED, abi.PYINS_NAV_DAMPED}
    assert np.mean(od["nav_mode"] == abi.PYINS_NAV_DAMPED) > 0.85
    assert od["n_ref_used"][-1, abi.PYINS_REF_SPEED_LOG - 1] == int(HOURS * 3600)
    assert od["fault_flags"][-1] == 0


def test_every_switch_is_bumpless(runs):
    _, (e, o) = runs
    switch = np.flatnonzero(np.diff(o["nav_mode"]) != 0)
    assert len(switch) >= 6                   # in and out of every turn
    dv, dp = metrics.record_steps(e)
    print(f"\n{len(switch)} switches: velocity error moves {dv[switch].max() * 1000:.2f} mm/s at most across "
          f"one, the position error {dp[switch].max():.2f} m")
    # the at-sea acceptance: < 1 cm/s and < 1 m across a switch (measured
    # 1.09 mm/s; the position error moves 0.46 m at most in that second, its
    # own rate then, the velocity error being up to ~0.5 m/s)
    assert dv[switch].max() < 0.01
    assert dp[switch].max() < 1.0


def test_the_engines_agree_with_damping(motion):
    """Three minutes, damping from ~70 s on, through both engines: the same
    modes and decisions, the floats to a few ulps."""
    n = 18_000
    refs = _log(motion, n * DT)
    a = _run(motion, n, refs, every=10)[1]
    b = _run(motion, n, refs, engine="reference", every=10)[1]
    assert np.count_nonzero(a["nav_mode"] == abi.PYINS_NAV_DAMPED) > 500
    engines.assert_engines_agree(a, b)
