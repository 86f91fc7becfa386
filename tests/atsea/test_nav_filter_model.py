"""The navigation filter's model beyond its 12 navigation and bias states
(nav_gyro_bias_rw; nav_table_scale_sigma and nav_table_mis_sigma, the
priors of the table-axis error states m_xz, m_yz, k_z;
csrc/src/nav_filter.hpp): what each does to the covariance, on the
reference (the C++ equals it: test_xcheck_nav_filter); that the firmware
reads them from its configuration; and that it estimates a table-axis
scale factor from the ship's data."""
import numpy as np

from pyins import contract, fil, metrics, sim
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


def _run(model, dtheta_z):
    """The filter over ticks whose z increments are dtheta_z, the IMU's
    attitude turning with them about the vertical (the table's moves)."""
    f = _filter(model)
    yaw = 0.0
    for dz in dtheta_z:
        yaw = yaw + dz
        nav_filter.gather(f, np.array([0.0, 0.0, 9.8 * DT]), dz)
        if f.ticks == f.prm.every:
            c, s = np.cos(yaw), np.sin(yaw)
            nav_filter.predict(f, _motion(), np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]))
    return f


# 0.7 s still; 180 deg at the default 6 deg/s: the time update's mean
# attitude over a 1-s interval is 6 deg of arc's chord, 5e-4 short of it
STILL, MOVE = np.zeros(70), np.full(3000, np.pi / 3000.0)


def test_a_move_turns_the_heading_by_the_scale_factor_and_the_reverse_move_takes_it_back():
    """k_z is a state: a 180-deg move adds (sigma_k pi)^2 to the heading's
    variance, and the reverse move, which the same k_z turns back, takes it
    away again (a term of Q, redrawn at every move as in ABI 0.18, would
    have added it twice)."""
    there = np.concatenate([STILL, MOVE, STILL])
    back = np.concatenate([there, -MOVE, STILL])
    span = (there.size // 100) * 100 * DT      # the time updates' (every 100 ticks)
    d = np.diag(_run(True, there).p - _run(False, there).p)
    # beyond the propagation (1e-4: the added variance propagated over 31 s
    # moves by < 1e-5 of itself)
    np.testing.assert_allclose(d[nav_filter.PHI + 2], (SCALE * np.pi) ** 2, rtol=1e-4)
    # the tilt: |int C(:, j) dalpha| over a half turn is 2 for x and for y,
    # so 2 (2 sigma_m)^2 over the two level axes (1e-2: the chord's 5e-4 and
    # the tilt's coupling to the velocity over 31 s)
    np.testing.assert_allclose(d[nav_filter.PHI + 0] + d[nav_filter.PHI + 1], 2.0 * (2.0 * MIS) ** 2, rtol=1e-2)
    np.testing.assert_allclose(d[nav_filter.EPS], RW * RW * span, rtol=1e-6)
    d2 = np.diag(_run(True, back).p - _run(False, back).p)
    # back where it started: what is left is the random walk's share and
    # the propagation, 1e-3 of one move's (sigma_k pi)^2
    assert abs(d2[nav_filter.PHI + 2]) < 1e-3 * (SCALE * np.pi) ** 2
    assert abs(d2[nav_filter.PHI + 0] + d2[nav_filter.PHI + 1]) < 1e-2 * 2.0 * (2.0 * MIS) ** 2


def test_the_table_states_not_modelled_stay_zero_and_healthy():
    """nav_table_*_sigma = 0: the three states keep a zero row and column of
    P through moves and updates, the filter stays healthy (a zero variance
    there is not a covariance fault) and the compensation stays 0."""
    f = _filter(False)
    yaw = 0.0
    dz_all = np.concatenate([STILL, MOVE, STILL, -MOVE, STILL])
    for k, dz in enumerate(dz_all):
        yaw = yaw + dz
        nav_filter.gather(f, np.array([0.0, 0.0, 9.8 * DT]), dz)
        if f.ticks == f.prm.every or k % 50 == 49:
            c, s = np.cos(yaw), np.sin(yaw)
            nav_filter.predict(f, _motion(), np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]))
        if k % 50 == 49:
            nav_filter.update_pair(f, nav_filter.POS, np.array([1.0, -2.0]), np.array([9.0, 9.0]))
            nav_filter.reset_feedback(f)
    assert f.healthy == 1
    assert not np.any(f.p[nav_filter.TAB:, :]) and not np.any(f.p[:, nav_filter.TAB:])
    assert not np.any(f.table_err)


def test_the_compensation_removes_what_the_table_states_hold():
    """compensate_gyro: dtheta_x -= m_xz dtheta_z, dtheta_y -= m_yz
    dtheta_z, dtheta_z -= k_z dtheta_z, after the biases."""
    f = _filter(True)
    f.gyro_bias = np.array([1e-7, -2e-7, 3e-7])
    f.table_err = np.array([5e-5, -4e-5, 2e-5])
    d = np.array([1e-4, -3e-4, 0.1])
    got = nav_filter.compensate_gyro(f, d, DT)
    want = d - f.gyro_bias * DT - f.table_err * d[2]
    np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-18)


def test_the_firmware_reads_the_model_from_its_configuration():
    """Two-position indexing on a ship at sea with GNSS: the heading sigma the
    firmware reports grows at the table's first move with
    nav_table_scale_sigma; before it only the ship's yaw and the Earth's
    rate act through k_z."""
    motion = sim.default_voyage(0.25, seed=1)
    n = int(900 / DT)
    g = references.gnss(motion, n * DT, seed=5)
    refs = g.refs.astype(contract.REF_DTYPE)
    base = dict(index_scheme=2, fine_sigma0_att_rad=np.array([2.0, 2.0, 10.0]) * ARCMIN_TO_RAD)
    sigma_k = 1e-3
    runs = {}
    for name, extra in (("off", {}), ("on", dict(nav_table_scale_sigma=sigma_k, nav_table_mis_sigma=0.0))):
        res = fil.run_fil(motion, n, config=dict(base, **extra), errors=sim.preset("error_free"), seed=1,
                          every=100, refs=refs, avail_tick=g.avail_tick)
        runs[name] = res.outputs
    off, on = runs["off"], runs["on"]
    moved = np.flatnonzero(np.abs(np.diff(np.unwrap(off["table_angle_rad"]))) > 1e-6)
    assert moved.size > 0, "the table never moved in 15 min of two-position indexing"
    first = moved[0]
    # before it: at most sigma_k times the IMU's turn so far (the ship's
    # yaw, and the Earth's rate: < 1e-3 rad in 15 min)
    yaw = np.unwrap(off["yaw_p_rad"][:first])
    turn = np.maximum.accumulate(np.abs(yaw - yaw[0])) + 1e-3
    grow = on["nav_sigma_heading_rad"][:first] - off["nav_sigma_heading_rad"][:first]
    # (-1e-9 rad: the two runs' feedback differs in its last bits)
    assert np.all(grow >= -1e-9) and np.all(grow <= sigma_k * turn)
    # 1e-3 of a 180-deg move is 10.8' of heading: the sigma after it at least 5' above
    after = on["nav_sigma_heading_rad"][first:] - off["nav_sigma_heading_rad"][first:]
    assert np.max(after) > 5.0 * ARCMIN_TO_RAD
    # the estimate stays 0 (an error-free IMU) within what 1 h of the sigma
    # allows: 1 sigma of the prior
    assert np.max(np.abs(on["nav_table_err"][:, 2])) < sigma_k
    assert not np.any(off["nav_table_err"])


def test_the_level_states_carry_the_earth_rate_through_the_level_gyros():
    """The IMU still with x east, y north: the y gyro senses the Earth's
    north rate W_N, so m_xy (x's sensitivity to the y rate) is an east
    drift m_xy W_N, and one 1-s time update correlates phi_E with m_xy by
    -W_N T sigma^2 (phi' = -C(:,0) m_xy w_y); m_yx sees w_x = 0: nothing."""
    prm = _filter(False).prm
    prm.level_mis = MIS
    f = nav_filter.init(prm, np.eye(3))
    lat = 34.0 * DEG_TO_RAD
    w_p = earth.OMEGA_IE * np.array([0.0, np.cos(lat), np.sin(lat)])
    for _ in range(100):
        nav_filter.gather(f, np.array([0.0, 0.0, 9.8 * DT]), w_p * DT)
    nav_filter.predict(f, _motion(), np.eye(3))
    want = -w_p[1] * 1.0 * MIS ** 2
    # 1e-4: the second-order terms of Phi are W T = 7e-5 of the first
    np.testing.assert_allclose(f.p[nav_filter.PHI + 0, nav_filter.LEV + 2], want, rtol=1e-4)
    assert f.p[nav_filter.PHI + 0, nav_filter.LEV + 3] == 0.0
    assert f.p[nav_filter.PHI + 1, nav_filter.LEV + 3] == 0.0


def _heading_run(told):
    """2 h of the voyage with GNSS and two-position indexing, an IMU whose
    only errors are level gyros misaligned to each other by +40" and -40"
    (the gyro triad yawed 40" against the accelerometers: a heading error of
    40" = 0.67' that neither GNSS nor indexing can show); told: the filter
    carries nav_level_mis_sigma of 30"."""
    motion = sim.default_voyage(2.0, seed=1)
    n = int(2.0 * 3600 / DT)
    g = references.gnss(motion, n * DT, seed=7)
    mis = np.zeros((3, 3))
    mis[0, 1], mis[1, 0] = 40.0 * ARCMIN_TO_RAD / 60.0, -40.0 * ARCMIN_TO_RAD / 60.0
    errors = sim.SensorErrors(gyro_misalignment=mis)
    # the filter told seed 002's grade of bias and noise (tools/nees_gnss.py
    # --prior seed002), so that its heading sigma is 0.1'-0.2', not the
    # default prior's 0.4'
    cfg = dict(index_scheme=2, fine_sigma0_att_rad=np.array([2.0, 2.0, 10.0]) * ARCMIN_TO_RAD,
               fine_sigma0_gyro=0.003 * DEG_TO_RAD / 3600.0, fine_sigma0_accel=30e-6 * G0,
               fine_gyro_arw=0.0005 * DEG_TO_RAD / 60.0, fine_accel_vrw=5e-6 * G0,
               nav_level_mis_sigma=(30.0 * ARCMIN_TO_RAD / 60.0) if told else 0.0)
    res = fil.run_fil(motion, n, config=cfg, errors=errors, seed=1, every=100,
                      refs=g.refs.astype(contract.REF_DTYPE), avail_tick=g.avail_tick)
    e = metrics.nav_errors(res)
    late = e.time_s >= 3600.0
    return e.att_n_rad[late, 2], res.outputs["nav_sigma_heading_rad"][late]


def test_a_yawed_gyro_triad_is_inside_the_heading_sigma_only_when_told():
    """Not told, the heading error (the triad's 40" yaw: 0.67') sits outside
    3 sigma of a filter that believes 0.1'; told 30" of level misalignment,
    the sigma covers it (|error| < 3 sigma all through the second hour)."""
    err, sig = _heading_run(False)
    assert np.median(np.abs(err) / sig) > 3.0
    err, sig = _heading_run(True)
    assert np.all(np.abs(err) < 3.0 * sig)


def test_the_nees_tool_splits_the_errors_the_filter_models_from_those_it_leaves_out():
    """tools/nees_gnss.py --errors seed002-draws-modelled: a unit of seed
    002's production with only what the 19 states carry: the biases, the
    gyros' scale factors and the misalignments of the x and y gyros kept
    as drawn, the rest 0."""
    from pyins.sim.sensors import draw_random_constants
    from tools_loader import load_tool
    tool = load_tool("nees_gnss.py")
    full = draw_random_constants("seed002", 10)
    cut = tool.modelled_only(full)
    for kept in ("gyro_bias", "gyro_scale", "accel_bias", "gyro_arw", "accel_vrw"):
        assert np.array_equal(getattr(cut, kept), getattr(full, kept)), kept
    assert np.array_equal(cut.gyro_misalignment[:2], full.gyro_misalignment[:2])
    assert np.all(full.gyro_misalignment[2, :2] != 0.0) and not np.any(cut.gyro_misalignment[2])
    assert np.any(full.accel_misalignment) and not np.any(cut.accel_misalignment)
    assert np.any(full.accel_scale) and not np.any(cut.accel_scale)


def test_a_y_accelerometer_misaligned_to_x_reads_a_turn_as_a_heading_error_does():
    """What the filter does not carry (docs/concepts.md, "The filter"): the
    firmware unaided through the voyage's first course change (115 deg at
    0.33 deg/s, 611-962 s; still water), the IMU error-free but for the y
    accelerometer misaligned to the x one by a_yx = 60" (y senses a_yx
    f_x). The velocity error it leaves against an error-free run is the
    integral of C_p^n(:,1) a_yx f_x with f from the truth (the table at 0:
    p = b, x to starboard, so the turn's centripetal force and the heel's
    gravity act along x, and the error runs along the track, as a heading
    error's does). Measured 7.55 mm/s, the integral 7.80. Bound: 10 % of
    it, the Schuler loop's reshaping of a velocity error over the 6 min of
    the turn ((w_s t)^2 / 2 = 7 %), and 3 deg of direction (1.8 measured)."""
    from pyins.open_loop import navigate
    from pyins.reference import attitude
    hours = 0.27
    motion = sim.default_voyage(hours, seed=1, sea=None, heave=())
    n = int(round(hours * 3600 / DT))
    mis = np.zeros((3, 3))
    mis[1, 0] = 60.0 * ARCMIN_TO_RAD / 60.0
    runs = [navigate(motion, n, every=100, sensors=sim.SensorModel(e, seed=0))
            for e in (sim.SensorErrors(gyro_arw=0.0, accel_vrw=0.0),
                      sim.SensorErrors(gyro_arw=0.0, accel_vrw=0.0, accel_misalignment=mis))]
    dv = runs[1].outputs["vel_n_mps"][-1, :2] - runs[0].outputs["vel_n_mps"][-1, :2]
    tr = runs[0].truth
    t = runs[0].outputs["tick"] * DT
    c = np.moveaxis(attitude.quat_to_mat(np.asarray(tr.quat_nb).T), -1, 0)   # every record at once
    f_n = np.gradient(tr.vel_n, t, axis=0) + np.array([0.0, 0.0, 9.8])
    f_x = np.einsum("ki,ki->k", c[:, :, 0], f_n)
    want = np.sum(c[:, :2, 1] * (mis[1, 0] * f_x)[:, None], axis=0) * (t[1] - t[0])
    assert np.linalg.norm(want) > 5e-3        # the turn is in the window
    assert np.linalg.norm(dv - want) <= 0.10 * np.linalg.norm(want)
    assert np.dot(dv, want) >= np.cos(np.radians(3.0)) * np.linalg.norm(dv) * np.linalg.norm(want)


def test_the_error_budget_weights_its_terms_as_a_unit_draws_them():
    """tools/nav_error_budget.py sums the heading errors of seed 002's terms,
    each run alone at its +1 sigma, weighted with a unit's normals: that
    sum is the unit's own error only if each term's run holds what the
    draw puts there. Summed the same way, the terms' error sets give unit
    12's random constants exactly (every one: the draws are exact
    multiples of the sigmas), and the budget's split into what the 19
    states carry is the nees tool's modelled_only."""
    from dataclasses import fields
    from pyins.sim.sensors import draw_random_constants, random_constant_normals
    from tools_loader import load_tool
    tool = load_tool("nav_error_budget.py")
    nees = load_tool("nees_gnss.py")
    unit = draw_random_constants("seed002", 12)
    z = random_constant_normals(12)
    constants = ("gyro_bias", "gyro_scale", "gyro_misalignment", "accel_bias", "accel_scale",
                 "accel_misalignment")
    total = {name: np.zeros_like(getattr(unit, name)) for name in constants}
    modelled = {name: np.zeros_like(getattr(unit, name)) for name in constants}
    for _, field, idx, carried in tool.TERMS:
        one = tool._term_errors(field, idx)
        for name in constants:
            total[name] += tool._normal_of(field, idx, z) * getattr(one, name)
            if carried:
                modelled[name] += tool._normal_of(field, idx, z) * getattr(one, name)
    cut = nees.modelled_only(unit)
    for name in constants:
        assert np.allclose(total[name], getattr(unit, name), rtol=1e-12, atol=0.0), name
        # the accelerometers' z bias is not a state (the vertical is held) but modelled_only keeps it
        want = getattr(cut, name).copy()
        if name == "accel_bias":
            want[2] = 0.0
        assert np.allclose(modelled[name], want, rtol=1e-12, atol=0.0), name
    assert len(tool.TERMS) == sum(np.count_nonzero(getattr(sim.preset("seed002"), f.name))
                                  for f in fields(unit) if f.name in constants)
