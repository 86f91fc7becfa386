"""``pyins replay`` tells the navigation filter the IMU's grade
(``--nav-table-scale``, ``--nav-table-mis``, ``--nav-level-scale``,
``--nav-level-mis``, ``--nav-gyro-bias-rw``; docs/cli.md, "pyins replay"):
the states a rotating IMU needs at sea, which before were reachable only
through a scenario file (whose truth a recorded log does not have). Each
is the scenario key's quantity with its unit, bounded as the key is; 0
means "not modelled", as it does there and in the core."""
import numpy as np
import parked_site
import pytest

from pyins import __main__ as cli

LOG = "tests/data/lasergyro_300s.imu.gz"
SITE = ["--lat", str(parked_site.LAT), "--lon", str(parked_site.LON), "--height", str(parked_site.H),
        "--coarse", "120", "--zero-velocity"]
GRADE = ["--nav-table-scale", "10 ppm", "--nav-table-mis", "10 arcsec", "--nav-level-scale", "10 ppm",
         "--nav-level-mis", "10 arcsec"]


def _outputs(tmp_path, *extra):
    out = tmp_path / "out"
    rc = cli.main(["replay", LOG, *SITE, "--out", str(out), "--quiet", *extra])
    assert rc == 0
    return np.load(out / "navigation.npz")["outputs"]


def test_the_grade_reaches_the_filter_on_real_data(tmp_path):
    """Told, the filter estimates the seven scale factors and misalignments
    (the record's nav_table_err, nav_level_err move off 0 once zero velocity
    is used); not told, they stay exactly 0 (not modelled)."""
    told = _outputs(tmp_path / "told", *GRADE)
    plain = _outputs(tmp_path / "plain")
    assert np.any(told["nav_table_err"] != 0.0) and np.any(told["nav_level_err"] != 0.0)
    assert not np.any(plain["nav_table_err"]) and not np.any(plain["nav_level_err"])
    # a parked vehicle's 180 s cannot move them far from 0: within 3 sigma
    # of the priors (10 ppm, 10")
    assert np.abs(told["nav_level_err"][:, :2]).max() < 30e-6
    assert np.abs(told["nav_level_err"][:, 2:]).max() < 30.0 * np.pi / 180.0 / 3600.0


@pytest.mark.parametrize("option, value, says", [
    ("--nav-level-mis", "-1 arcsec", "at least 0 arcsec"),
    ("--nav-table-scale", "0.02", "at most 0.01"),
    ("--nav-table-mis", "10", "unit"),
    ("--nav-gyro-bias-rw", "1 deg/h", "deg/h"),
    ("--nav-level-scale", "nan ppm", "start with a number"),
])
def test_a_grade_the_filter_cannot_take_is_refused_naming_the_option(tmp_path, capsys, option, value, says):
    rc = cli.main(["replay", LOG, *SITE, "--out", str(tmp_path / "out"), "--quiet", option, value])
    err = capsys.readouterr().err
    assert rc == 2
    assert option in err and says in err, err
    assert not (tmp_path / "out" / "summary.json").exists()
