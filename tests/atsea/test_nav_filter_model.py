"""The navigation filter's model beyond its bias states (nav_gyro_bias_rw,
nav_table_scale_sigma, nav_table_mis_sigma; csrc/src/nav_filter.hpp):
what each adds to the covariance, on the reference (the C++ equals it:
test_xcheck_nav_filter), and that the firmware reads them from its
configuration (a run with them differs from one without, only after a
table move for the table's terms)."""
import numpy as np

from pyins import contract, fil, sim
from pyins.reference import earth, nav_filter
from pyins.sim import references
from pyins.units import ARCMIN_TO_RAD, DEG_TO_RAD, DT, G0

SCALE, MIS = 10e-6, 10.0 * ARCMIN_TO_RAD / 60.0     # seed 002's grade: 10 ppm, 10 arcsec
RW = 0.001 * DEG_TO_RAD / 3600.0 / 60.0             # 0.001 deg/h/sqrt(h)


def _filter(model):
    prm = nav_filter.Params(dt=DT, every=100, reject_limit=10, gyro_arw=0.001 * DEG_TO_RAD / 60.0,
                            accel_vrw=10e-6 * G0, gate=13.8155,
                            sigma0_att=np.array([1.0, 1.0, 10.0]) * ARCMIN_TO_RAD, sigma0_vel=0.1,
                            sigma0_pos=10.0, sigma0_gyro=0.01 * DEG_TO_RAD / 3600.0,
                            sigma0_accel=100e-6 * G0, gyro_bias_rw=RW if model else 0.0,
                            table_scale=SCALE if model else 0.0, table_mis=MIS if model else 0.0)
    return nav_filter.init(prm, np.eye(3))


def _motion():
    lat = 34.0 * DEG_TO_RAD
    rm, rn = earth.principal_radii(np.sin(lat))
    return nav_filter.Motion(np.sin(lat), np.cos(lat), rm, rn, 0.0, 0.0)


def _run(model, dalpha):
    f = _filter(model)
    for k, da in enumerate(dalpha):
        nav_filter.gather(f, np.array([0.0, 0.0, 9.8 * DT]), da)
        if f.ticks == f.prm.every:
            nav_filter.predict(f, _motion(), np.eye(3))
    return f


def test_a_move_adds_its_whole_angle_squared():
    """A 180-deg move spread over two time updates adds (sigma pi)^2 in all,
    not the sum of the per-interval squares (the error is a fixed fraction of
    the whole move); a stop restarts the move's angle."""
    still, move = np.zeros(70), np.full(60, np.pi / 60.0)
    dalpha = np.concatenate([still, move, still])          # 200 ticks: two updates, the move across both
    on, off = _run(True, dalpha), _run(False, dalpha)
    span = 200 * DT
    d = np.diag(on.p - off.p)
    # what the time updates add beyond the propagation (1e-20 rad^2: the
    # propagation of the added variance over 1 s moves it by < 1e-6 of itself)
    np.testing.assert_allclose(d[nav_filter.PHI + 2], (SCALE * np.pi) ** 2, rtol=1e-4)
    np.testing.assert_allclose(d[nav_filter.PHI + 0], (MIS * np.pi) ** 2, rtol=1e-2)
    np.testing.assert_allclose(d[nav_filter.EPS], RW * RW * span, rtol=1e-6)
    # two moves of 90 deg with a stop between: twice (sigma pi / 2)^2, half the one move's
    half = np.full(30, np.pi / 60.0)
    two = np.concatenate([still[:40], half, still[:60], half, still[:70]])
    d2 = np.diag(_run(True, two).p - _run(False, two).p)
    np.testing.assert_allclose(d2[nav_filter.PHI + 2], 2.0 * (SCALE * np.pi / 2.0) ** 2, rtol=1e-4)


def test_no_move_no_table_term():
    """A table standing still adds nothing to the attitude: with the bias
    random walk off, the model changes nothing."""
    f = _filter(True)
    f.prm.gyro_bias_rw = 0.0
    for _ in range(300):
        nav_filter.gather(f, np.array([0.0, 0.0, 9.8 * DT]), 0.0)
        if f.ticks == f.prm.every:
            nav_filter.predict(f, _motion(), np.eye(3))
    np.testing.assert_array_equal(f.p, _run(False, np.zeros(300)).p)


def test_the_firmware_reads_the_model_from_its_configuration():
    """Two-position indexing on a ship at sea with GNSS: the heading sigma the
    firmware reports grows at each table move with nav_table_scale_sigma and
    stays as without until the first move."""
    motion = sim.default_voyage(0.25, seed=1)
    n = int(900 / DT)
    g = references.gnss(motion, n * DT, seed=5)
    refs = g.refs.astype(contract.REF_DTYPE)
    base = dict(index_scheme=2, fine_sigma0_att_rad=np.array([2.0, 2.0, 10.0]) * ARCMIN_TO_RAD)
    runs = {}
    for name, extra in (("off", {}), ("on", dict(nav_table_scale_sigma=1e-3, nav_table_mis_sigma=0.0))):
        res = fil.run_fil(motion, n, config=dict(base, **extra), errors=sim.preset("error_free"), seed=1,
                          every=100, refs=refs, avail_tick=g.avail_tick)
        runs[name] = (res.outputs["nav_sigma_heading_rad"], res.outputs["table_angle_rad"])
    s_off, table = runs["off"]
    s_on, _ = runs["on"]
    moved = np.flatnonzero(np.abs(np.diff(np.unwrap(table))) > 1e-6)
    assert moved.size > 0, "the table never moved in 15 min of two-position indexing"
    first = moved[0]
    np.testing.assert_array_equal(s_on[:first], s_off[:first])
    # 1e-3 of a 180-deg move is 10.8' of heading: the sigma after it at least 5' above
    assert np.max(s_on[first:] - s_off[first:]) > 5.0 * ARCMIN_TO_RAD
