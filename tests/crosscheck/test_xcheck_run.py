"""Whole runs: the C++ firmware against the NumPy reference firmware.

Ten minutes (60,000 ticks) of a random swing profile with a turning table:
attitude within 1e-9 rad and position within 1 mm. Per-step differences of
~1e-16 (Eigen vs NumPy summation order, portable vs libm sin/cos) are
amplified by the Schuler loop and Earth-rate coupling but stay far below
these bounds; an algorithmic difference (a dropped term, a wrong sign, a
different branch) would not.
"""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pyins import native, scenario, sim
from pyins.reference import attitude, earth
from pyins.reference import firmware as ref_firmware
from pyins import units

DEG = units.DEG_TO_RAD


@st.composite
def swing_profiles(draw):
    lat = draw(st.floats(-70.0, 70.0)) * DEG
    amp = np.array([draw(st.floats(0.0, 16.0)) for _ in range(3)]) * DEG
    freq = np.array([draw(st.floats(0.02, 0.3)) for _ in range(3)])
    phase = np.array([draw(st.floats(0.0, 6.28)) for _ in range(3)])
    yaw0 = draw(st.floats(-np.pi, np.pi))
    motion = sim.Swing(lat, draw(st.floats(-3.0, 3.0)), draw(st.floats(0.0, 50.0)),
                       draw(st.floats(-3.0, 3.0)) * DEG, draw(st.floats(-3.0, 3.0)) * DEG, yaw0,
                       amp, freq, phase)
    rate = draw(st.sampled_from([0.0, 6.0 * DEG, -6.0 * DEG]))
    return motion, sim.ConstantRate(rate, alpha0=draw(st.floats(0.0, 6.28)))


@settings(max_examples=3, deadline=None)
@given(profile=swing_profiles())
def test_ten_minutes_cpp_equals_reference(profile):
    motion, table = profile
    n = 60_000
    dtheta, dv, alpha = sim.exact_increments(motion, n, table=table)
    cfg = scenario.initial_config(motion, table)
    out_c = native.Firmware(cfg).run(native.make_samples(dtheta, dv, alpha), every=1000)
    ref = ref_firmware.Firmware(cfg)
    keep = []
    for k in range(n):
        status, out = ref.step(dtheta[k], dv[k], alpha[k])
        assert status == 0
        if (k + 1) % 1000 == 0:
            keep.append(out)
    assert len(keep) == len(out_c)
    for c, r in zip(out_c, keep):
        assert c["tick"] == r["tick"]
        q_err = attitude.quat_mul(c["quat_np"], attitude.quat_conj(r["quat_np"]))
        assert np.linalg.norm(attitude.quat_to_rotvec(attitude.quat_normalize(q_err))) < 1e-9
        rm, rn = earth.principal_radii(np.sin(r["lat_rad"]))
        dn = (c["lat_rad"] - r["lat_rad"]) * rm
        de = (c["lon_rad"] - r["lon_rad"]) * rn * np.cos(r["lat_rad"])
        assert np.hypot(dn, de) < 1e-3
        assert abs(c["table_angle_rad"] - r["table_angle_rad"]) < 1e-9
