"""tools/papers/seed002_random_yaw.py runs what its results say: seed 002's
built-in with the sinusoid replaced by a NarrowbandYaw of the same RMS rate,
peak period, mean yaw, pitch and roll; the firmware started from the new
yaw's true attitude with Table 1's initial errors kept; the "check opened"
variant the flexible scheme with only its lag tolerance changed; both
readings of Table 1's heading."""
import numpy as np
import pytest

from pyins import scenario
from tools_loader import load_tool

ry = load_tool("papers/seed002_random_yaw.py")


def _same_but(a, b, key):
    """Configurations a and b equal in every field but ``key``."""
    keys = (set(a) | set(b)) - {key}
    for k in keys:
        np.testing.assert_array_equal(np.asarray(a[k]), np.asarray(b[k]), err_msg=k)


@pytest.mark.parametrize("convention", ["ccw", "clockwise"])
def test_the_random_yaw_stands_in_for_the_sinusoid(convention):
    base = ry.job_spec(2, None, "flexible", 1, convention)
    spec = ry.job_spec(2, 5, "flexible", 1, convention)
    sinusoid, new = base.motion, spec.motion
    assert type(new).__name__ == "NarrowbandYaw" and new.seed == 5
    assert (new.pitch, new.roll, new.yaw0) == tuple(sinusoid.mean)
    assert new.rms_rate == pytest.approx(sinusoid.rate_amplitude / np.sqrt(2.0), rel=1e-15)
    assert new.peak_period == sinusoid.period == 60.0
    # Table 1's heading as the reading says: yaw +15 deg (ccw) or -15 deg (clockwise)
    assert np.degrees(sinusoid.mean[2]) == pytest.approx(15.0 if convention == "ccw" else -15.0)
    # the configured attitude minus the truth at t = 0: Table 1's initial error, unchanged
    err_base = np.asarray(base.config["euler_b_rad"]) - scenario.initial_truth(sinusoid)[4]
    err_new = np.asarray(spec.config["euler_b_rad"]) - scenario.initial_truth(new)[4]
    np.testing.assert_allclose(err_new, err_base, atol=1e-15)
    assert abs(err_base[2]) == pytest.approx(np.radians(1.0 / 60.0), rel=1e-6)   # 1'
    # everything else the built-in's
    _same_but(spec.config, base.config, "euler_b_rad")


def test_the_opened_check_changes_only_the_tolerance():
    a = ry.job_spec(1, 3, "flexible", 1)
    b = ry.job_spec(1, 3, "flexible, check opened", 1)
    _same_but(b.config, a.config, "index_tolerance_rad")
    assert "index_tolerance_rad" not in a.config
    assert b.config["index_tolerance_rad"] == pytest.approx(np.radians(10.0))
