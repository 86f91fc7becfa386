"""`pyins replay --coarse-method fit_vel`: the alignment under way on the
shipped real log (a ring-laser-gyro IMU on a parked site,
tests/data/README.md) with a receiver's fixes of the site, as a user would
run it, beside the moored ship's FIT on the same log; and refused before the
log runs when no GNSS velocity reaches its first seconds."""
import json
import pathlib

import numpy as np
import parked_site
import pytest

from pyins import __main__ as cli
from pyins.sim import references as R

ROOT = pathlib.Path(__file__).resolve().parents[2]
LOG = str(ROOT / "tests/data/lasergyro_300s.imu.gz")
SITE = ["--lat", str(parked_site.LAT), "--lon", str(parked_site.LON), "--height", str(parked_site.H),
        "--coarse", "120"]
NAV_NOT_YET = "the navigation filter aligning on the coarse attitude"


def _replay(tmp_path, name, *extra):
    out = tmp_path / name
    rc = cli.main(["replay", LOG, *SITE, "--reference", "parked", "--out", str(out), "--quiet", *extra])
    return rc, out


def test_the_real_log_aligns_under_way_as_fit_does_within_its_sigma(tmp_path):
    # 3 m fixes and 0.05 m/s velocities of the parked site at 1 Hz from the log's start
    refs = parked_site.fixes(np.arange(0, 30_001, 100), 3.0)
    R.save_refs_csv(str(tmp_path / "gnss.csv"), refs)
    got = {}
    for method in ("fit", "fit_vel"):
        rc, out = _replay(tmp_path, method, "--refs", str(tmp_path / "gnss.csv"), "--coarse-method", method)
        assert rc == 0
        s = json.loads((out / "summary.json").read_text())
        got[method] = (np.load(out / "navigation.npz")["outputs"], s)
    a, _ = got["fit"]
    b, s = got["fit_vel"]
    k = int(np.searchsorted(b["tick"], 29_900))
    # at 300 s the two alignments' headings within 3 sigma of the under-way one's
    # (measured 5.1' apart, sigma 17.1': 0.05 m/s of velocity noise over 120 s is 50'
    # of coarse sigma, which 180 s of fixes have not worked down to FIT's 15')
    assert abs(b["heading_b_rad"][k] - a["heading_b_rad"][k]) < 3.0 * b["nav_sigma_heading_rad"][k]
    # and it says it is not aligned yet, in the summary
    assert not (b["state_flags"][-1] & 1)
    assert any(NAV_NOT_YET in w for w in s["warnings"])
    assert int(np.bitwise_or.reduce(b["fault_flags"])) == 0
    # which alignment ran and how sure it was, in the summary and on the page
    al = s["aligned"]
    assert al["method"] == "coarse FIT_VEL (under way) 120 s, then the navigation filter while a reference aids it"
    k_nav = int(np.searchsorted(b["tick"], 12_000))          # the first navigation record, 120 s
    assert al["heading_sigma_arcmin"] == pytest.approx(np.degrees(b["nav_sigma_heading_rad"][k_nav]) * 60.0,
                                                       rel=1e-9)
    page = (tmp_path / "fit_vel" / "report.html").read_text()
    assert "coarse FIT_VEL (under way) 120 s" in page and "heading sigma" in page


def test_a_replay_with_references_is_rerun_into_its_own_output(tmp_path):
    # its references.png is its own: the second run replaces the first (it was refused as
    # "files that are not a replay's")
    refs = parked_site.fixes(np.arange(0, 30_001, 100), 3.0)
    R.save_refs_csv(str(tmp_path / "gnss.csv"), refs)
    for _ in range(2):
        rc, out = _replay(tmp_path, "again", "--refs", str(tmp_path / "gnss.csv"), "--coarse-method", "fit")
        assert rc == 0
    assert (out / "references.png").exists()


@pytest.mark.parametrize("first_s", [None, 10])
def test_an_alignment_under_way_without_a_velocity_from_its_start_is_refused(tmp_path, capsys, first_s):
    extra = []
    if first_s is not None:
        refs = parked_site.fixes(np.arange(first_s * 100, 30_001, 100), 3.0)
        R.save_refs_csv(str(tmp_path / "late.csv"), refs)
        extra = ["--refs", str(tmp_path / "late.csv")]
    rc, out = _replay(tmp_path, "out", "--coarse-method", "fit_vel", *extra)
    assert rc == 2
    err = capsys.readouterr().err
    assert "--coarse-method fit_vel" in err and "GNSS" in err
    assert ("none is given" if first_s is None else f"the first is at {first_s:g} s") in err
    assert not out.exists()
