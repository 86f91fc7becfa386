"""Hypothesis over streams of references (the at-sea acceptance 7): random
interleavings of steps and pushes (the five kinds used, kinds refused, in
order and out of order, ahead, late and beyond the horizon, NaN values, bad
sigmas, fixes that fit, fixes near the gate and outliers, repeats of the
last fix)
through both engines. At every push the C++ core and the NumPy mirror give
the same status; a refused push changes nothing (the snapshot after it is
the one before); after every block of steps the records make the same
decisions (references used, rejected, stale, skipped; the mode; the
references in use; the fault bits) and their floats agree to a few ulps;
the covariance stays positive definite (no KF_NOT_PD, every sigma finite
and positive, the position sigma bounded by its prior when position fixes
come)."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pyins import contract, engine
from pyins.reference import abi, earth

LAT = 0.5
G = 9.7946                              # near normal gravity at 28.6 deg: a static IMU, tilt-free
RM = earth.principal_radii(np.sin(LAT))[0]
INTEGER = ("tick", "mode", "nav_mode", "ref_in_use", "n_ref_used", "n_ref_rejected", "n_ref_stale",
           "n_ref_skipped", "fault_flags", "state_flags")
FLOAT = ("lat_rad", "lon_rad", "vel_n_mps", "nav_nis", "nav_sigma_pos_m", "nav_sigma_heading_rad",
         "nav_gyro_bias_rad_s", "nav_accel_bias_mps2")


def _static(n):
    return contract.make_samples(np.zeros((n, 3)), np.tile([0.0, 0.0, G * 0.01], (n, 1)))


# one operation: ("step", ticks) or ("push", kind, tick offset, value style, sigma style)
_push = st.tuples(st.just("push"),
                  st.sampled_from([1, 1, 2, 2, 3, 4, 5, 9]),           # used kinds mostly; a refused one
                  # ticks from now: late .. beyond the 10 s horizon, and the edges
                  # (1 s of latency: -100; the horizon: +1000) often
                  st.one_of(st.integers(-150, 1_100),
                            st.sampled_from([-101, -100, -99, -50, -1, 0, 1, 999, 1_000, 1_001])),
                  st.sampled_from(["fit", "fit", "fit", "near", "near", "outlier", "nan", "repeat"]),
                  st.sampled_from(["ok", "ok", "ok", "ok", "zero", "nan", "negative"]))
_step = st.tuples(st.just("step"), st.integers(1, 400))
# a fix pushed ahead, then stepped past: the filter's gate meets it (most of a stream)
_fix = st.tuples(st.just("fix"), st.sampled_from([1, 2, 3, 4, 5]), st.integers(1, 200),
                 st.sampled_from(["fit", "near", "near", "outlier", "repeat"]), st.integers(1, 300))
_ops = st.lists(st.one_of(_push, _step, _fix, _fix), min_size=4, max_size=30)


def _ref(kind, tick, style, sigma_style, n_pushed):
    sig = {"ok": 3.0 if kind == 1 else 0.05, "zero": 0.0, "nan": np.nan, "negative": -1.0}[sigma_style]
    if kind == 1:                       # a position fix at the site: a distinct longitude each push
        lat, lon = LAT, 1e-12 * n_pushed
        if style == "outlier":
            lat += 300.0 / RM
        elif style == "near":           # 6-50 m off: a NIS about the gate's 13.8 for some P
            lat += 6.0 * 1.35 ** (n_pushed % 8) / RM
        elif style == "repeat":
            lon = 0.0
        value = [lat, lon, 0.0]
    else:
        v = 1e-4 * (n_pushed % 7) if style != "repeat" else 0.0
        off = {"outlier": 3.0, "near": 0.05 * 1.35 ** (n_pushed % 8)}.get(style, 0.0)
        value = [v + off, -v, 0.0]
    if style == "nan":
        value[0] = np.nan
    return contract.make_refs(int(kind), [int(tick)], [value], [[sig, sig, sig]])


def _same_records(a, b):
    assert a.shape == b.shape
    for name in INTEGER:
        assert np.array_equal(a[name], b[name]), name
    for name in FLOAT:
        np.testing.assert_allclose(a[name], b[name], rtol=1e-9, atol=1e-12, err_msg=name)


@settings(max_examples=60, deadline=None)
@given(ops=_ops, nav_mode=st.sampled_from([abi.PYINS_NAV_AUTO, abi.PYINS_NAV_AUTO, abi.PYINS_NAV_UNDAMPED,
                                            abi.PYINS_NAV_DAMPED]))
def test_streams_of_references_in_both_engines(ops, nav_mode):
    cfg = {"lat_rad": LAT, "nav_mode": nav_mode}
    undamped = nav_mode == abi.PYINS_NAV_UNDAMPED
    damped = nav_mode == abi.PYINS_NAV_DAMPED
    fws = [engine.firmware(e, cfg) for e in ("native", "reference")]
    for fw in fws:
        fw.run(_static(50))
    pushed = 0
    for op in ops:
        if op[0] == "step":
            recs = [fw.run(_static(op[1])) for fw in fws]
            _same_records(*recs)
            out = recs[0]
            # the covariance stays positive definite (the filter's own check sets KF_NOT_PD)
            assert np.all(out["fault_flags"] & abi.PYINS_FAULT_KF_NOT_PD == 0)
            if not undamped:
                assert np.all(np.isfinite(out["nav_sigma_pos_m"])) and np.all(out["nav_sigma_pos_m"] > 0.0)
                assert np.all(np.isfinite(out["nav_sigma_heading_rad"]))
                assert np.all(out["nav_sigma_heading_rad"] > 0.0)
            if damped:
                # never a filter correction; DAMPED only while a velocity reference is in use
                assert not np.any(out["nav_mode"] == abi.PYINS_NAV_INTEGRATED)
                assert not np.any(out["nav_gyro_bias_rad_s"])
                assert np.all((out["nav_mode"] == abi.PYINS_NAV_DAMPED) <= (out["ref_in_use"] != 0))
            continue
        if op[0] == "fix":
            _, kind, ahead, style, steps = op
            ref = _ref(kind, int(fws[0].output()["tick"]) + ahead, style, "ok", pushed)
            pushed += 1
            got = []
            for fw in fws:
                try:
                    fw.push_ref(ref)
                    got.append("PYINS_OK")
                except contract.RefError as e:     # (undamped, a full queue, out of order)
                    got.append(e.status_name)
            assert got[0] == got[1], (op, got)
            _same_records(*[fw.run(_static(steps)) for fw in fws])
            continue
        _, kind, offset, style, sigma_style = op
        now = int(fws[0].output()["tick"])
        ref = _ref(kind, now + offset, style, sigma_style, pushed)
        pushed += 1
        got = []
        for fw in fws:
            before = fw.snapshot()
            try:
                fw.push_ref(ref)
                got.append("PYINS_OK")
            except contract.RefError as e:
                got.append(e.status_name)
                assert fw.snapshot() == before, e.status_name       # refused: nothing changed
        assert got[0] == got[1], (op, got)
        # the refusals a push must get, whatever came before
        if undamped or (damped and kind == 1):
            assert got[0] == "PYINS_E_REF_UNUSED"
        elif kind not in (1, 2, 3, 4, 5):
            assert got[0] == "PYINS_E_REF_KIND"
        elif style == "nan" or sigma_style != "ok":
            assert got[0] == "PYINS_E_REF_VALUE"
        elif offset > 1_000:
            assert got[0] == "PYINS_E_REF_FUTURE"
        elif offset < -100:
            assert got[0] == "PYINS_E_REF_ORDER"
    # the outcome of the whole stream, alike
    a, b = (fw.output() for fw in fws)
    _same_records(a[None], b[None])


@settings(max_examples=40, deadline=None)
@given(fixes=st.lists(_fix, min_size=20, max_size=60))
def test_sustained_aiding_meets_the_gate_alike(fixes):
    """Long runs of fixes (fits, fixes 6-50 m or 0.05-0.5 m/s off whose NIS
    falls about the gate, outliers, repeats): the same decisions at the
    gate in both engines, fix after fix, and a covariance that stays
    positive definite."""
    fws = [engine.firmware(e, {"lat_rad": LAT}) for e in ("native", "reference")]
    for fw in fws:
        fw.run(_static(50))
    for pushed, (_, kind, ahead, style, steps) in enumerate(fixes):
        ref = _ref(kind, int(fws[0].output()["tick"]) + ahead, style, "ok", pushed)
        got = []
        for fw in fws:
            try:
                fw.push_ref(ref)
                got.append("PYINS_OK")
            except contract.RefError as e:         # a full queue, or behind the last pushed
                got.append(e.status_name)
        assert got[0] == got[1] and got[0] in ("PYINS_OK", "PYINS_E_REF_FULL", "PYINS_E_REF_ORDER")
        recs = [fw.run(_static(steps)) for fw in fws]
        _same_records(*recs)
        assert np.all(recs[0]["fault_flags"] & abi.PYINS_FAULT_KF_NOT_PD == 0)
        assert np.all(recs[0]["nav_sigma_pos_m"] > 0.0) and np.all(np.isfinite(recs[0]["nav_sigma_pos_m"]))
