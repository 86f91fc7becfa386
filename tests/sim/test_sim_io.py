"""IMU sample files: bit-exact round trips and clear errors on malformed input,
through `pyins.sim.io`, the names users have imported (the format itself is
`pyins.logs.project`)."""
import numpy as np
import pytest

from pyins import logs, sim
from pyins.logs import project
from pyins.sim import imu, io, motion, turntable


def sample_arrays(n=500, seed=0):
    rng = np.random.default_rng(seed)
    dtheta = rng.normal(0, 1e-3, (n, 3))
    dv = rng.normal(0, 1e-2, (n, 3)) + [0, 0, 0.0980665]
    angle = rng.uniform(0, 2 * np.pi, n)
    # awkward values: signed zero, subnormal, tiny/huge, 1/3, pi, ulp neighbours
    dtheta[0] = [-0.0, 5e-324, 1e-300]
    dtheta[1] = [1.0 / 3.0, np.pi, np.nextafter(1.0, 2.0)]
    dv[0] = [1e300, -2.2250738585072014e-308, np.nextafter(0.1, 0.0)]
    angle[0] = np.nextafter(2 * np.pi, 0.0)
    return dtheta, dv, angle


def same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def test_npz_round_trip(tmp_path):
    dtheta, dv, angle = sample_arrays()
    path = tmp_path / "run.npz"
    meta = {"profile": "bad", "seed": 7, "sensors": "seed002", "lat_rad": 0.5235987755982988}
    io.save_npz(path, dtheta, dv, angle, 0.01, metadata=meta, tick=np.arange(10, 510))
    data = io.load_npz(path)
    assert same_bits(data.dtheta_p, dtheta) and same_bits(data.dv_p, dv)
    assert same_bits(data.table_angle_rad, angle)
    np.testing.assert_array_equal(data.tick, np.arange(10, 510))
    assert data.dt == 0.01 and data.metadata == meta
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]


def test_csv_round_trip(tmp_path):
    dtheta, dv, angle = sample_arrays()
    path = tmp_path / "run.csv"
    io.save_csv(path, dtheta, dv, angle)
    lines = path.read_text().splitlines()
    assert lines[0] == io.CSV_HEADER
    assert lines[0] == ("tick,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,"
                        "dv_x_mps,dv_y_mps,dv_z_mps,table_angle_rad")
    assert len(lines) == 501 and lines[1].startswith("1,")
    data = io.load_csv(path, dt=0.01)
    assert same_bits(data.dtheta_p, dtheta) and same_bits(data.dv_p, dv)
    assert same_bits(data.table_angle_rad, angle)
    np.testing.assert_array_equal(data.tick, np.arange(1, 501))
    assert data.dt == 0.01


def test_csv_of_simulated_run(tmp_path):
    mo = motion.sea_state("bad", 0.5, 2.0, 0.0, 0.3)
    th, dv, angle = imu.exact_increments(mo, 300, table=turntable.ConstantRate(0.1))
    io.save_csv(tmp_path / "a.csv", th, dv, angle)
    data = io.load_csv(tmp_path / "a.csv")
    assert same_bits(data.dtheta_p, th) and same_bits(data.dv_p, dv)
    assert same_bits(data.table_angle_rad, angle)


GOOD_ROW = "1,1e-3,2e-3,3e-3,0.1,0.2,9.8,0.5"


@pytest.mark.parametrize("text, where, what", [
    ("tick,dtheta_x,dtheta_y,dtheta_z,dv_x,dv_y,dv_z,angle\n" + GOOD_ROW + "\n",
     "line 1", "header"),
    ("", "line 1", "header"),
    (io.CSV_HEADER + "\n" + GOOD_ROW + "\n2,1,2,3,4,5,6\n", "line 3", "expected 8 columns"),
    (io.CSV_HEADER + "\n" + GOOD_ROW + "\n2,1,2,3,4,5,6,7,8\n", "line 3", "got 9"),
    (io.CSV_HEADER + "\n" + GOOD_ROW + "\n2,1,2,x3,4,5,6,7\n",
     "line 3, column 4 (dtheta_z_rad)", "not a number"),
    (io.CSV_HEADER + "\n" + GOOD_ROW + "\n2,1,2,3,4,5,6,\n",
     "line 3, column 8 (table_angle_rad)", "not a number"),
    (io.CSV_HEADER + "\n" + GOOD_ROW + "\n1,1,2,3,4,5,6,7\n",
     "line 3, column 1 (tick)", "does not increase"),
    (io.CSV_HEADER + "\n" + GOOD_ROW + "\n3,1,2,3,4,5,6,7\n\n2,1,2,3,4,5,6,7\n",
     "line 5, column 1 (tick)", "previous tick 3 on line 3"),
    (io.CSV_HEADER + "\n1.5,1,2,3,4,5,6,7\n", "line 2, column 1 (tick)", "not an integer"),
])
def test_csv_malformed(tmp_path, text, where, what):
    path = tmp_path / "bad_input.csv"
    path.write_text(text)
    with pytest.raises(ValueError) as info:
        io.load_csv(path)
    msg = str(info.value)
    assert "bad_input.csv" in msg and where in msg and what in msg, msg


def test_npz_malformed(tmp_path):
    path = tmp_path / "broken.npz"
    np.savez(path, dtheta_p=np.zeros((3, 3)), dv_p=np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"broken\.npz: missing arrays"):
        io.load_npz(path)
    path = tmp_path / "shapes.npz"
    with open(path, "wb") as f:
        np.savez(f, tick=np.arange(3), dtheta_p=np.zeros((3, 2)), dv_p=np.zeros((3, 3)),
                 table_angle_rad=np.zeros(3), dt=np.float64(0.01), metadata=np.array("{}"))
    with pytest.raises(ValueError, match=r"shapes\.npz: expected dtheta_p \(N, 3\)"):
        io.load_npz(path)
    path = tmp_path / "text.npz"
    path.write_text("not a zip file")
    with pytest.raises(ValueError, match=r"text\.npz: not a readable \.npz"):
        io.load_npz(path)


def test_save_rejects_bad_arrays(tmp_path):
    with pytest.raises(ValueError, match="out.csv"):
        io.save_csv(tmp_path / "out.csv", np.zeros((3, 3)), np.zeros((2, 3)), np.zeros(3))
    with pytest.raises(ValueError, match="not strictly increasing"):
        io.save_npz(tmp_path / "out.npz", np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(3),
                    0.01, tick=[1, 3, 2])


def test_the_simulators_names_are_the_log_formats():
    """pyins.sim.io and pyins.sim keep the names of the file format that moved
    to pyins.logs.project: the same objects, not copies."""
    for name in io.__all__:
        assert getattr(io, name) is getattr(project, name) is getattr(logs, name)
        assert getattr(sim, name) is getattr(project, name)
