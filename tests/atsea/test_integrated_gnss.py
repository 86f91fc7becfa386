"""The integrated navigation filter with GNSS on a ship under way: a 1-h
voyage (pyins.sim.default_voyage(1, seed=1): 15.5 -> 11.5 kn, turns of
-115 and +61 deg, the general sea state's swing and heave) with seed 002's
sensor errors (biases, scale factors, misalignments, noise), the IMU fixed
to the ship (no indexing: what the ship's motion alone makes observable),
an initial attitude error of 1', -1', 5' (E, N, U), and a 1 Hz GNSS
(pyins.sim.references.gnss: 3 m / 0.05 m/s white noise, a 2 m first-order
Gauss-Markov bias over 300 s) with its faults. Measured on the landed code
(2026-12-04), the figures the bounds below hold with margin:

    clean:     horizontal RMS after 10 min 1.7 m (the bias is not a state:
               it passes through), unaided the same hour 1.4 km
    outliers:  1 % of fixes jumped 50-500 m: every one rejected, RMS +3 %
    frozen:    10 min of the same fix repeated: the repeats unused, the
               position kind out of use with REF_REJECTED, 11.5 m at the
               freeze's end (the INS alone), 2 m a minute after it
    offset:    1 km for 10 min: every offset fix rejected, REF_REJECTED,
               the error stays under 3 m throughout

and the two engines (C++, NumPy mirror) make the same decisions over 60 s
of the voyage with GNSS, their floats within a few ulps."""
import engines
import numpy as np
import pytest

from pyins import contract, metrics, sim
from pyins.open_loop import navigate
from pyins.reference import abi
from pyins.scenario.build import initial_errors
from pyins.sim import references
from pyins.units import ARCMIN_TO_RAD, DT

HOURS = 1.0
N = int(HOURS * 3600 / DT)
POS = abi.PYINS_REF_GNSS_POS - 1     # the slot of the per-kind arrays
VEL = abi.PYINS_REF_GNSS_VEL - 1


@pytest.fixture(scope="module")
def motion():
    return sim.default_voyage(HOURS, seed=1)


def _config(motion):
    err = initial_errors(motion, phi=np.array([1.0, -1.0, 5.0]) * ARCMIN_TO_RAD)
    return dict(err, fine_sigma0_att_rad=np.array([2.0, 2.0, 10.0]) * ARCMIN_TO_RAD)


def _run(motion, n=N, engine="native", every=100, **gnss):
    """(errors, records, references); a fresh sensor model each run: the
    same noise draws in every variant."""
    refs = avail = None
    g = None
    if gnss.pop("aided", True):
        g = references.gnss(motion, n * DT, seed=5, **gnss)
        refs, avail = g.refs.astype(contract.REF_DTYPE), g.avail_tick
    res = navigate(motion, n, every=every, sensors=sim.SensorModel(sim.preset("seed002"), seed=3),
                   config=_config(motion), refs=refs, avail_tick=avail, engine=engine)
    return metrics.nav_errors(res), res.outputs, g


def _rms(e, t0_s=600):
    return float(np.sqrt(np.mean(e.horizontal_m[t0_s:] ** 2)))


@pytest.fixture(scope="module")
def clean(motion):
    return _run(motion)


def test_gnss_holds_the_position_and_the_filter_is_consistent(motion, clean):
    e, o, _ = clean
    unaided, _, _ = _run(motion, aided=False)
    # 3 m: the at-sea acceptance's horizontal bound for this GNSS (its 2 m
    # correlated bias passes through a loosely coupled filter that does not
    # model it); measured 1.7 m. Unaided the same hour drifts > 1 km.
    assert _rms(e) <= 3.0
    assert _rms(unaided) > 300.0 * _rms(e)
    assert set(o["nav_mode"][1:]) == {abi.PYINS_NAV_INTEGRATED}
    assert np.all(o["state_flags"][1:] & abi.PYINS_STATE_POS_AIDED)
    assert o["fault_flags"][-1] == 0
    # the heading error within 3 of the filter's own sigmas after 20 min
    # (the turns and the Earth rate make it observable here; no indexing)
    late = slice(1200, None)
    assert np.all(np.abs(e.att_n_rad[late, 2]) <= 3.0 * o["nav_sigma_heading_rad"][late])
    # velocity innovations consistent: mean NIS of a 2-D pair is 2 while the
    # model holds; 3000 pairs, correlated by the filter: [1.7, 2.3] (the
    # position pair reads ~1.5: the reported sigma sqrt(3^2 + 2^2) is that of
    # white noise, the bias is slower)
    assert 1.7 <= np.mean(o["nav_nis"][600:, VEL]) <= 2.3
    assert 1.0 <= np.mean(o["nav_nis"][600:, POS]) <= 2.3


def test_outliers_are_rejected_one_by_one(motion, clean):
    e, o, g = _run(motion, outlier_rate=0.01)
    pos = g.refs[g.refs["kind"] == abi.PYINS_REF_GNSS_POS]
    truth = g.truth_value[g.refs["kind"] == abi.PYINS_REF_GNSS_POS]
    north = (pos["value"][:, 0] - truth[:, 0]) * 6.37e6     # [m], enough to find a 50 m jump
    east = (pos["value"][:, 1] - truth[:, 1]) * 6.37e6 * np.cos(truth[:, 0])
    jumped = pos["tick"][np.hypot(north, east) > 40.0]
    assert len(jumped) > 20
    # a record every second; a fix of tick T (no latency) reaches the
    # firmware once tick T is stepped, after that tick's record: the used
    # count between the records of T and T + 100 s does not move for a jump
    used = o["n_ref_used"][:, POS].astype(np.int64)
    k = np.searchsorted(o["tick"], jumped)
    assert np.all(o["tick"][k] == jumped) and k[-1] + 1 < len(used)
    assert np.all(used[k + 1] == used[k])
    # and every other fix but a few (the gate's 0.1 % and the bias) is used
    assert np.count_nonzero(np.diff(used) == 0) <= len(jumped) + 10
    # within 10 % of the clean run (the acceptance's bound)
    assert _rms(e) <= 1.10 * _rms(clean[0])
    assert o["fault_flags"][-1] & abi.PYINS_FAULT_REF_REJECTED == 0


def test_a_frozen_receiver_is_dropped_and_navigation_goes_on(motion):
    e, o, _ = _run(motion, frozen=[(1800.0, 2400.0)])
    assert o["fault_flags"][-1] & abi.PYINS_FAULT_REF_REJECTED
    during = (o["tick"] > 1830 * 100) & (o["tick"] < 2400 * 100)
    # out of use (ref_in_use says it) and never used while frozen
    assert np.all(o["ref_in_use"][during] & (1 << POS) == 0)
    assert np.all(np.diff(o["n_ref_used"][during, POS].astype(np.int64)) == 0)
    assert o["n_ref_stale"][-1, POS] >= 590
    # the INS alone for 10 min: tens of metres at most (measured 11.5 m),
    # then the fixes are taken again (2 m a minute after)
    assert e.horizontal_m[during].max() < 30.0
    assert e.horizontal_m[2460:].max() < 5.0


def test_an_offset_receiver_is_rejected_and_navigation_goes_on(motion):
    e, o, _ = _run(motion, offsets=[(1800.0, 2400.0, (1000.0, 0.0, 0.0))])
    assert o["fault_flags"][-1] & abi.PYINS_FAULT_REF_REJECTED
    during = (o["tick"] > 1800 * 100) & (o["tick"] < 2400 * 100)
    assert np.all(np.diff(o["n_ref_used"][during, POS].astype(np.int64)) == 0)
    assert o["n_ref_rejected"][-1, POS] >= 600
    # the velocity still aids; measured < 3 m throughout
    assert e.horizontal_m[600:].max() < 5.0
    assert np.all(o["ref_in_use"][o["tick"] > 2500 * 100] & (1 << POS))


def test_the_engines_agree_on_a_voyage_with_gnss(motion):
    n = 6000
    a = _run(motion, n=n, every=1, pos_noise_m=(1.0, 1.0, 1.0))[1]
    b = _run(motion, n=n, engine="reference", every=1, pos_noise_m=(1.0, 1.0, 1.0))[1]
    # fixes at 1 s, 2 s, ... 59 s are in the last record (the one of 60 s
    # arrives after it)
    assert a["n_ref_used"][-1, POS] + a["n_ref_rejected"][-1, POS] == 59
    # every decision alike (which fix was used or rejected, the mode, the
    # reference in use), the floats to a few ulps (tests/engines.py)
    engines.assert_engines_agree(a, b)
