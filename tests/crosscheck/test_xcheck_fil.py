"""Firmware in the loop: the compiled plant + C++ firmware against the NumPy
plant (pyins.sim.turntable) + NumPy reference firmware, tick for tick over a
short closed-loop run with indexing, noise and quantisation. The two loops
see the same noise; per-tick differences are ulps (glibc vs NumPy sin/cos,
BLAS vs Eigen order), far below the bounds: attitude 1e-10 rad, table angle
1e-10 rad, the indexing decisions identical."""
import numpy as np
import pytest

from pyins import fil, native, scenario, sim
from pyins.reference import attitude
from pyins.reference import firmware as ref_firmware
from pyins.sim import turntable
from pyins import units

DEG = units.DEG_TO_RAD


@pytest.mark.parametrize("scheme, sums", [(2, 0), (4, 0), (6, 1), (7, 0)])
def test_fil_cpp_equals_numpy(scheme, sums):
    m = sim.HeadingSwing.experiment(1)
    n = 1500
    errors = sim.preset("seed002")
    errors.gyro_quantum = 1e-7
    errors.accel_quantum = 1e-5
    cfg = dict(index_scheme=scheme, index_stop_ticks=300, seq_mode=1,   # the plant counts its packets
               index_sums=sums)
    res = fil.run_fil(m, n, config=cfg, errors=errors, seed=3, every=1)

    # the NumPy loop with the same noise draw
    fw = ref_firmware.Firmware(scenario.initial_config(m, None, **cfg))
    st = turntable.PlantState()
    tab = turntable.TableConfig()
    mats = turntable.error_matrices(errors)
    omega, force, x, w = sim.node_rates(m, np.arange(n))
    z = np.random.default_rng(3).standard_normal((n, 6))
    sq = np.sqrt(0.01)
    moved = 0
    for k in range(n):
        g, a, enc, seq = turntable.plant_tick(tab, st, mats, omega[k], force[k], x, w,
                                              errors.gyro_arw * sq * z[k, :3], errors.accel_vrw * sq * z[k, 3:],
                                              0.01)
        status, r = fw.step(g, a, enc, seq)
        assert status == 0
        st.rate_cmd_rad_s = r["motor_rate_cmd_rad_s"]
        c = res.outputs[k]
        assert c["seq"] == r["seq"] == k + 1, k      # both plants count the IMU's packets alike
        assert abs(res.plant["alpha_rad"][k] - st.alpha_rad) < 1e-10, k
        for f in ("index_state", "index_step", "index_fallbacks", "index_motor_starts"):
            assert c[f] == r[f], (k, f)
        assert abs(c["index_travel_rad"] - r["index_travel_rad"]) < 1e-9, k
        q_err = attitude.quat_mul(c["quat_np"], attitude.quat_conj(r["quat_np"]))
        assert np.linalg.norm(attitude.quat_to_rotvec(attitude.quat_normalize(q_err))) < 1e-10, k
        moved += c["index_state"] == 2
    assert moved > 50


def test_periodic_ship_motion_is_tiled_exactly():
    """Tiling one period of the ship's node rates equals computing them."""
    m = sim.sea_state("bad", 0.6, 0.0, 0.0, yaw0=1.0)
    p = sim.periodic_ticks(m, units.DT)
    assert p == 1000                       # 0.2 and 0.3 Hz: 5 s and 3.33 s -> 10 s
    o1, f1, _, _ = sim.node_rates(m, np.arange(3) + 7)
    o2, f2, _, _ = sim.node_rates(m, np.arange(3) + 7 + 5 * p)
    np.testing.assert_allclose(o2, o1, rtol=0, atol=1e-15)
    np.testing.assert_allclose(f2, f1, rtol=0, atol=1e-13)
    assert sim.periodic_ticks(sim.Manoeuvre.default(0.6, 0.0, 0.0, 0.0), units.DT) is None
