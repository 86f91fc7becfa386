"""Scenario files: built-ins, units, the resolved form and its digest,
overrides, one clear line per mistake, and a short run through the firmware."""
import json
import math
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from pyins import metrics, run_scenario, scenario, sim
from pyins.reference import attitude
from pyins.scenario import ScenarioError
from pyins.units import UNITS, parse_quantity
from pyins import units
from tools_loader import load_tool

ROOT = Path(__file__).resolve().parents[2]
DEG = units.DEG_TO_RAD
BUILTINS = ["demo", "seed000_static", "seed000_swing", "seed001_fine5", "seed001_fine8",
            "seed002_exp1", "seed002_exp2", "seed003",
            "moored_bad", "moored_general", "moored_ideal", "moored_spectrum",   # test_scenario_ship.py
            "harbour_ranging",                                                  # test_harbour_ranging.py
            "voyage_gnss", "voyage_gnss_outages", "voyage_log", "voyage_dvl",   # tests/atsea/test_scenario_refs.py
            "pier_indexed", "moored_indexed",                                   # tests/physics/test_indexed_alignment.py
            "at_anchor",                                                        # tests/physics/test_anchor_alignment.py
            "under_way"]                                                        # tests/physics/test_underway_alignment.py


def _tool(name):
    """tools/papers/<name>.py as a module (the scripts that reproduce the papers)."""
    return load_tool(f"papers/{name}.py")


# Seed 002 as the paper sets it up (Table 1 initial errors, the schemes, the constant-rate turns),
# written out here to check the built-ins seed002_exp* that tools/papers/reproduce_seed002.py runs.
SEED002_PAPER = {1: (8.57, 3.70, 2.97), 2: (16.13, 12.90, 1.98)}
SEED002_SCHEMES = ((0, "no rotation"), (2, "traditional two-position"), (4, "flexible two-position"),
                   (6, "flexible, derivation form"))
SEED002_PAPER_ACCEL = 600.0 * DEG        # 6 deg/s within one tick: the paper's constant-rate turns
SEED002_PLANT_ACCEL = 1000.0 * DEG       # a motor that can follow SEED002_PAPER_ACCEL


#: Seed 003's bounds (its Figs. 4-9), as tools/papers/reproduce_seed003.py prints them.
SEED003_PAPER = {"position_nmi": 1.1, "level_arcmin": 0.01, "heading_arcmin": 0.3, "velocity_mps": 0.06}


# Seed 001's static fine alignment (docs/papers.md, seed 001 §3; latitude ours).
SEED001_LAT = 34.246 * DEG
SEED001_EULER = np.array([-5.0, 2.0, 235.0]) * DEG
SEED001_PHI0 = np.array([10.0, 10.0, 60.0]) * units.ARCMIN_TO_RAD
SEED001_N = 1200 * units.TICK_HZ                 #: 1200 s of fine alignment [ticks]


# Seed 000's coarse alignment (docs/papers.md, seed 000 §2): its bias levels with the noise of
# seeds 002/003 (the same class of IMU), the static base at Xi'an and Table 2's swings.
SEED000_LAT, SEED000_LON = 34.246 * DEG, 108.910 * DEG


def seed000_errors():
    e = sim.preset("error_free")
    e.gyro_arw = sim.preset("seed002").gyro_arw       # 0.0005 deg/sqrt(h)
    e.accel_vrw = sim.preset("seed002").accel_vrw     # 5 ug/sqrt(Hz)
    e.gyro_bias = np.full(3, 0.01 * units.DPH_TO_RPS)
    e.accel_bias = np.full(3, 100.0 * units.UG_TO_MPS2)
    return e


def seed000_motion(state, heading):
    yaw = -heading * DEG
    if state == "static":
        return sim.Static(SEED000_LAT, SEED000_LON, 0.0, 0.5 * DEG, -0.3 * DEG, yaw)
    return sim.sea_state(state, SEED000_LAT, SEED000_LON, 0.0, yaw0=yaw)


def seed002_initial_errors(m):
    """Seed 002 Table 1 errors on the true initial state of ``m``: pitch -10", roll 10",
    heading +1' (yaw -1'), velocity 0.01 m/s east and north, position 10 m north and east."""
    return scenario.initial_errors(m, pitch=-10.0 * units.ARCSEC_TO_RAD, roll=10.0 * units.ARCSEC_TO_RAD,
                                   yaw=-60.0 * units.ARCSEC_TO_RAD, velocity=[0.01, 0.01, 0.0],
                                   north=10.0, east=10.0)


def assert_same_motion(a, b):
    """Same profile: the same class and bit-identical states at a few times."""
    assert type(a) is type(b)
    t = np.array([0.0, 1.234, 60.0, 3599.99])
    sa, sb = a.state(t), b.state(t)
    for f in ("lat", "lon", "height", "vel_n", "euler", "euler_rate"):
        assert np.array_equal(getattr(sa, f), getattr(sb, f)), f


def assert_same_errors(a, b):
    for f in fields(sim.SensorErrors):
        assert np.array_equal(getattr(a, f.name), getattr(b, f.name)), f.name


def assert_same_config(ours, theirs):
    """Our config holds the tool's keys with bit-identical values; the only
    extra key allowed is index_scheme = 0 (the firmware's default)."""
    for key, value in theirs.items():
        assert np.array_equal(np.asarray(ours[key]), np.asarray(value)), key
    for key in set(ours) - set(theirs):
        assert key == "index_scheme" and ours[key] == 0, key


# ---------------------------------------------------------------------------
# Built-ins
# ---------------------------------------------------------------------------
def test_list_builtin_names_and_titles():
    names = [n for n, _ in scenario.list_builtin()]
    assert names == sorted(BUILTINS)
    assert all(title and title != name for name, title in scenario.list_builtin())


@pytest.mark.parametrize("name", BUILTINS)
def test_builtin_loads_resolves_and_gives_runs(name):
    sc = scenario.load(name)
    assert sc.name == name and Path(sc.source) == scenario.builtin_path(name)
    res = sc.resolved()
    assert json.loads(json.dumps(res, allow_nan=False)) == res
    runs = list(sc.runs())
    assert [r.label for r in runs] == sc.labels and len(runs) >= 1
    for i, r in enumerate(runs):
        assert r.index == i and r.scenario == name and r.dt == 0.01
        assert r.duration_ticks == round(sc.duration_s * 100) and r.every == 100
        assert isinstance(r.errors, sim.SensorErrors) and isinstance(r.motion, sim.Motion)
    # loading by path gives the same scenario
    assert scenario.load(scenario.builtin_path(name)).digest() == sc.digest()
    # a built-in names only metrics and variants that exist
    for fig in sc.paper["figures"]:
        assert fig["metric"] in scenario.METRICS
        assert fig["variant"] is None or fig["variant"] in sc.labels


def test_seed002_builtins_match_reproduce_seed002():
    tool = _tool("reproduce_seed002")
    assert tool.PAPER == SEED002_PAPER and tool.VIDS[:4] == tuple(str(s) for s, _ in SEED002_SCHEMES)
    for exp in (1, 2):
        sc = scenario.load(f"seed002_exp{exp}")
        runs = list(sc.runs())
        m = sim.HeadingSwing.experiment(exp)
        assert [r.config["index_scheme"] for r in runs] == [s for s, _ in SEED002_SCHEMES]
        assert [r.label for r in runs] == [label for _, label in SEED002_SCHEMES]
        for r in runs:
            assert_same_motion(r.motion, m)
            assert_same_errors(r.errors, sim.preset("seed002"))
            want = dict(index_scheme=r.config["index_scheme"], index_accel_rad_s2=SEED002_PAPER_ACCEL)
            want.update(seed002_initial_errors(m))
            assert r.table.accel_max_rad_s2 == SEED002_PLANT_ACCEL
            assert_same_config(r.config, want)
            assert r.seed == 1 and r.duration_ticks == int(72.0 * 360_000)
        paper = [f["value_si"] / units.NMI_TO_M for f in sc.paper["figures"]]
        assert paper == pytest.approx(SEED002_PAPER[exp], rel=1e-12)


def test_seed003_builtin_matches_reproduce_seed003():
    tool = _tool("reproduce_seed003")
    assert tool.PAPER == SEED003_PAPER
    runs = list(scenario.load("seed003").runs())
    assert [r.config for r in runs] == [dict(index_scheme=0), dict(index_scheme=1)]
    for r in runs:
        assert_same_motion(r.motion, sim.Static(34.246 * DEG, 108.91 * DEG, 0.0))
        assert_same_errors(r.errors, sim.preset("seed003"))
        assert r.seed == 1 and r.duration_ticks == int(24.0 * 360_000)
    figs = {f["metric"]: f for f in scenario.load("seed003").paper["figures"]}
    assert figs["horizontal_error_max"]["value_si"] == pytest.approx(
        SEED003_PAPER["position_nmi"] * units.NMI_TO_M)
    assert figs["level_error_max"]["value_si"] == pytest.approx(
        SEED003_PAPER["level_arcmin"] * units.ARCMIN_TO_RAD)
    assert figs["velocity_error_max"]["relation"] == "<"


@pytest.mark.parametrize("states", [5, 8])
def test_seed001_builtins_match_reproduce_seed001(states):
    tool = _tool("reproduce_seed001")
    assert tool.SCENARIOS[states] == f"seed001_fine{states}"
    (r,) = scenario.load(f"seed001_fine{states}").runs()
    assert_same_motion(r.motion, sim.Static(SEED001_LAT, 108.91 * DEG, 0.0, *SEED001_EULER))
    assert_same_errors(r.errors, sim.preset("seed001"))
    guess = attitude.mat_to_euler(attitude.rotvec_to_mat(-SEED001_PHI0)
                                  @ attitude.euler_to_mat(SEED001_EULER))
    assert_same_config(r.config, dict(euler_b_rad=guess, fine_ticks=SEED001_N, fine_states=states))
    assert r.seed == 0 and r.duration_ticks == SEED001_N


def test_seed000_builtins_match_reproduce_seed000():
    tool = _tool("reproduce_seed000")
    assert tool.HEADINGS == (0, 60, 120, 180, 240, 300)
    assert (tool.LAT, tool.LON) == (SEED000_LAT, SEED000_LON)
    assert_same_errors(tool.sensors(seed=3)[1], seed000_errors())
    runs = list(scenario.load("seed000_static").runs())
    assert [r.seed for r in runs] == [1000 * 0 + s for s in range(5)]
    for r in runs:
        assert_same_motion(r.motion, seed000_motion("static", 0))
        assert_same_errors(r.errors, seed000_errors())
        assert_same_config(r.config, dict(coarse_ticks=15_000, coarse_ratio=0.5,
                                          euler_b_rad=[0.0, 0.0, 0.0]))
    runs = list(scenario.load("seed000_swing").runs())
    for r, state in zip(runs, ("ideal", "general", "bad")):
        assert_same_motion(r.motion, seed000_motion(state, 0))
        assert_same_errors(r.errors, seed000_errors())
        assert_same_config(r.config, dict(coarse_ticks=20_000, coarse_ratio=0.5,
                                          euler_b_rad=[0.0, 0.0, 0.0]))
        assert r.seed == 7 + 1000 * 0 + 0


def test_demo_builtin_matches_pyins_demo():
    (r,) = scenario.load("demo").runs()
    assert_same_motion(r.motion, sim.HeadingSwing.experiment(1))
    assert_same_errors(r.errors, sim.preset("seed002"))
    assert r.config == {"index_scheme": 0} and r.seed == 1 and r.duration_ticks == 2 * 360_000


def test_docs_name_every_key_and_builtin():
    doc = (ROOT / "docs" / "scenarios.md").read_text()
    tables = [scenario.TOP_KEYS, scenario.STEP_KEYS, scenario.SEGMENT_KEYS, scenario.FIGURE_KEYS,
              *scenario.TABLES.values(), *scenario.MOTION_KINDS.values(),
              *scenario.REFERENCE_TABLES.values(), scenario.WINDOW_KEYS]
    for keys in tables:
        for name in keys:
            assert f"`{name}`" in doc, name
    for name in [*BUILTINS, *scenario.METRICS, *scenario.INDEX_SCHEMES]:
        assert f"`{name}`" in doc, name


# ---------------------------------------------------------------------------
# Resolved form, digest, overrides
# ---------------------------------------------------------------------------
MINIMAL = """
duration = "1 h"
[motion]
kind = "static"
"""


def test_resolved_is_si_and_json_round_trips():
    sc = scenario.loads(MINIMAL + 'lat = "45 deg"\n[sensors]\ngyro_bias = "0.01 deg/h"\n')
    res = sc.resolved()
    assert res["duration_s"] == 3600.0 and res["motion"]["lat_rad"] == 45.0 * DEG
    assert res["sensors"]["gyro_bias_rad_s"] == [0.01 * units.DPH_TO_RPS] * 3
    assert res["firmware"]["coarse_time_s"] is None          # the firmware's default
    assert json.loads(sc.resolved_json()) == res


def test_digest_is_stable_and_follows_the_values():
    text = scenario.builtin_path("seed002_exp1").read_text()
    a = scenario.loads(text, source="a.toml", name="seed002_exp1")
    b = scenario.loads(text, source="elsewhere/b.toml", name="seed002_exp1")
    assert a.digest() == b.digest() == scenario.load("seed002_exp1").digest()
    assert len(a.digest()) == 64
    # the values count, not how they are written
    same = scenario.loads(text.replace('duration = "72 h"', 'duration = "259200 s"'), name="seed002_exp1")
    assert same.digest() == a.digest()
    assert a.with_overrides({"seed": 1}).digest() == a.digest()
    # any change of a value changes it
    changed = {a.with_overrides(o).digest() for o in (
        {"seed": 2}, {"motion.lat": "34.2461 deg"}, {"initial_errors.north": "11 m"},
        {"sensors.gyro_bias": "0.0031 deg/h"}, {"compare.values": ["none", "two_position", "flexible", "four_position"]},
        {"indexing.stop": "300 s"})}
    assert len(changed) == 6 and a.digest() not in changed


def test_with_overrides_returns_a_new_validated_scenario():
    sc = scenario.load("seed002_exp1")
    sc2 = sc.with_overrides({"seed": 3, "motion.yaw": "60 deg"})
    r0, r2 = next(sc.runs()), next(sc2.runs())
    assert r2.seed == 3 and r0.seed == 1                     # the original is unchanged
    assert sc2.resolved()["motion"]["yaw_rad"] == 60.0 * DEG  # yaw replaced heading
    assert "heading" not in sc2.data["motion"] and "heading" in sc.data["motion"]
    assert "(with overrides)" in sc2.source
    # None removes a key: back to the default (no initial north error)
    sc3 = sc.with_overrides({"initial_errors.north": None})
    assert "lat_rad" not in next(sc3.runs()).config
    with pytest.raises(ScenarioError, match=r"\(with overrides\): motion.yaw: out of range"):
        sc.with_overrides({"motion.yaw": "400 deg"})
    with pytest.raises(ScenarioError, match=r"motoin.yaw: unknown table 'motoin'; did you mean 'motion'\?"):
        sc.with_overrides({"motoin.yaw": "1 deg"})


def test_compare_over_any_key_and_default_labels():
    sc = scenario.loads(MINIMAL + '[compare]\nkey = "sensors.gyro_bias"\n'
                        'values = ["0.001 deg/h", "0.01 deg/h"]\n')
    runs = list(sc.runs())
    assert [r.label for r in runs] == ["sensors.gyro_bias = 0.001 deg/h", "sensors.gyro_bias = 0.01 deg/h"]
    assert runs[1].errors.gyro_bias[0] == 0.01 * units.DPH_TO_RPS
    assert sc.resolved()["variants"][0]["label"] == runs[0].label


def test_custom_scheme_and_manoeuvre_and_table():
    text = """
duration = "30 min"
[motion]
kind = "manoeuvre"
heading = "90 deg"
[turntable]
initial_angle = "90 deg"
fault = "stall"
fault_time = "100 s"
[indexing]
scheme = "custom"
rate = "6 deg/s"
acceleration = "30 deg/s^2"
delta = 0.01
[[indexing.steps]]
stop = "60 s"
move = "flex_cos"
angle = "180 deg"
[[indexing.steps]]
stop = "6000 ticks"
move = "fixed"
angle = "-180 deg"
"""
    (r,) = scenario.loads(text).runs()
    assert isinstance(r.motion, sim.Manoeuvre) and r.motion.yaw0 == -90.0 * DEG
    assert r.config["index_steps"] == [(6000, 2, math.pi), (6000, 1, -math.pi)]
    assert r.config["index_n_steps"] == 2 and r.config["index_scheme"] == 5
    assert r.config["table_angle_rad"] == 90.0 * DEG
    assert r.table.fault == sim.turntable.TABLE_STALL and r.table.fault_tick == 10_000
    assert "index_sums" not in r.config                  # seed 002's rule unless asked
    (r,) = scenario.loads(text.replace('delta = 0.01', 'delta = 0.01\nsums = "all"')).runs()
    assert r.config["index_sums"] == 1
    legs = "\n".join(['[[motion.segments]]\nkind = "accelerate"\nduration = "60 s"\nspeed = "5 knot"',
                      '[[motion.segments]]\nkind = "turn"\nduration = "30 s"\nangle = "45 deg"'])
    (r,) = scenario.loads('duration = "90 s"\n[motion]\nkind = "manoeuvre"\n' + legs).runs()
    assert r.motion.duration == 90.0 and r.motion.segments[0].value == 5 * 1852.0 / 3600.0


# ---------------------------------------------------------------------------
# Units
# ---------------------------------------------------------------------------
def test_units_agree_with_the_earth_constants_and_presets():
    q = parse_quantity
    assert q("1 deg", "angle") == units.DEG_TO_RAD
    assert q("1 arcmin", "angle") == q("1'", "angle") == units.ARCMIN_TO_RAD
    assert q("1 arcsec", "angle") == q('1"', "angle") == units.ARCSEC_TO_RAD
    assert q("1 deg/h", "angular_rate") == units.DPH_TO_RPS
    assert q("1 g", "acceleration") == units.G0
    assert q("1 ug", "acceleration") == q("1 µg", "acceleration") == units.UG_TO_MPS2
    assert q("1 nmi", "length") == units.NMI_TO_M
    # the preset values, bit for bit, from the way a file writes them
    p2 = sim.preset("seed002")
    assert q("0.003 deg/h", "angular_rate") == p2.gyro_bias[0]
    assert q("30 ug", "acceleration") == p2.accel_bias[0]
    assert q("0.0005 deg/sqrt(h)", "angle_random_walk") == p2.gyro_arw
    assert q("5 ug/sqrt(Hz)", "velocity_random_walk") == p2.accel_vrw
    assert q("10 ppm", "dimensionless") == p2.gyro_scale[0]
    assert q("10 arcsec", "angle") == p2.gyro_misalignment[0, 1]
    assert q("0.466 ppm", "dimensionless") == sim.preset("seed003").gyro_scale[0]


def test_unit_spellings():
    q = parse_quantity
    assert q("6 deg / s", "angular_rate") == q("6deg/s", "angular_rate") == q("6 °/s", "angular_rate")
    assert q("1 m/s²", "acceleration") == q("1 m/s**2", "acceleration") == 1.0
    assert q("2 deg/√h", "angle_random_walk") == q("2 deg/sqrt(h)", "angle_random_walk")
    assert q("5 ug/sqrt(hz)", "velocity_random_walk") == 5 * units.UG_TO_MPS2
    assert q("+1.5e-3 h", "time") == 5.4 and q(".5 min", "time") == 30.0
    assert q("150 ticks", "time", tick_hz=100) == 1.5
    assert q(0, "time") == 0.0 and q(0.25, "dimensionless") == 0.25 and q("1 %", "dimensionless") == 0.01


_VALUES = st.one_of(st.sampled_from([0.0, 1.0, -1.0, 0.003, 1e-9, 72.0, 123456.789]),
                    st.floats(-1e9, 1e9, allow_nan=False, allow_infinity=False))
_UNITS = st.sampled_from([(dim, unit) for dim, units in UNITS.items() for unit in units if unit])


@given(x=_VALUES, du=_UNITS)
@example(x=-0.0, du=("angle", "deg"))
def test_parse_is_number_times_factor(x, du):
    """Exact: the parser reads repr(x) back (repr round-trips) and multiplies
    by the unit's factor once, as the presets do."""
    dim, unit = du
    assert parse_quantity(f"{x!r} {unit}", dim) == x * UNITS[dim][unit]


@given(x=st.floats(1e-6, 1e6))
def test_units_are_consistent_with_each_other(x):
    """The same quantity in two units agrees to 1e-15 relative: each side is
    a few correctly rounded operations (<= 2**-53 each), so the two can
    differ by a few ulp, never more."""
    q = parse_quantity
    pairs = [(f"{x!r} deg/h", f"{x / 3600!r} deg/s", "angular_rate"),
             (f"{x!r} arcmin", f"{x * 60!r} arcsec", "angle"),
             (f"{x!r} deg/sqrt(h)", f"{x * 60!r} deg/h/sqrt(Hz)", "angle_random_walk"),
             (f"{x!r} mg", f"{x * 1000!r} ug", "acceleration"),
             (f"{x!r} knot", f"{x * 1852 / 3600!r} m/s", "velocity"),
             (f"{x!r} h", f"{x * 60!r} min", "time"),
             (f"{x!r} nmi", f"{x * 1.852!r} km", "length")]
    for a, b, dim in pairs:
        assert math.isclose(q(a, dim), q(b, dim), rel_tol=1e-15), (a, b)


@given(du=_UNITS, other=st.sampled_from(sorted(UNITS)))
def test_a_unit_of_another_dimension_is_named_as_such(du, other):
    dim, unit = du
    if unit in UNITS[other]:
        return
    with pytest.raises(ScenarioError) as exc:
        parse_quantity(f"1 {unit}", other, where="a.b")
    msg = str(exc.value)
    assert msg.startswith("a.b: ") and ("wrong unit" in msg or "unknown unit" in msg)
    assert ", ".join(u for u in UNITS[other] if u) in msg          # the accepted units listed


@pytest.mark.parametrize("value, dim, reason", [
    (72, "time", "missing unit: 72 is a plain number but a time needs a unit"),
    (0.003, "angular_rate", "such as '0.003 deg/h'"),
    ("72", "time", "missing unit in '72'"),
    ("3 deg/hr", "angular_rate", "unknown unit 'deg/hr'"),
    ("30 ug", "angular_rate", "wrong unit 'ug' in '30 ug': it is a unit of acceleration"),
    ("150 ticks", "time", "unknown unit 'ticks'"),          # no tick rate given
    ("deg", "angle", "does not start with a number"),
    (True, "angle", "got bool True"),
    (float("inf"), "dimensionless", "not a finite number"),
])
def test_unit_mistakes(value, dim, reason):
    with pytest.raises(ScenarioError) as exc:
        parse_quantity(value, dim, where="sensors.gyro_bias")
    assert str(exc.value).startswith("sensors.gyro_bias: ") and reason in str(exc.value)
    assert "\n" not in str(exc.value)


# ---------------------------------------------------------------------------
# One clear line per mistake: FILE: key: reason
# ---------------------------------------------------------------------------
MOTION = '[motion]\nkind = "static"\n'
MISTAKES = [
    # unknown keys, with the closest known key
    ("unknown top key", 'durration = "1 h"\n' + MOTION, "durration", "unknown key; did you mean 'duration'?"),
    ("unknown table key", 'duration = "1 h"\n' + MOTION + 'lattitude = "1 deg"\n', "motion.lattitude",
     "unknown key; did you mean 'lat'?"),
    ("key of another kind", 'duration = "1 h"\n' + MOTION + 'amplitude = "1 deg"\n', "motion.amplitude",
     "unknown key; known keys of motion kind 'static': kind, lat"),
    ("unknown step key", 'duration = "1 h"\n' + MOTION + '[indexing]\nscheme = "custom"\nrate = "6 deg/s"\n'
     'acceleration = "30 deg/s^2"\n[[indexing.steps]]\nstop = "1 s"\nmove = "fixed"\nangle = "1 deg"\n'
     'angel = "2 deg"\n', "indexing.steps[0].angel", "did you mean 'angle'?"),
    # units
    ("wrong unit", 'duration = "1 h"\n' + MOTION + '[sensors]\ngyro_bias = "30 ug"\n', "sensors.gyro_bias",
     "wrong unit 'ug' in '30 ug': it is a unit of acceleration, but an angular rate is wanted (units: rad/s"),
    ("missing unit", "duration = 72\n" + MOTION, "duration",
     "missing unit: 72 is a plain number but a time needs a unit"),
    ("missing unit in a list", 'duration = "1 h"\n' + MOTION + '[initial_errors]\n'
     'velocity = ["0.01 m/s", 0.01, "0 m/s"]\n', "initial_errors.velocity[1]", "missing unit"),
    ("not whole ticks", 'duration = "1.005 s"\n' + MOTION, "duration", "not a whole number of 0.01 s ticks"),
    # ranges
    ("latitude", 'duration = "1 h"\n' + MOTION + 'lat = "95 deg"\n', "motion.lat",
     "out of range: '95 deg' must be >= -89.9 deg and <= 89.9 deg"),
    ("negative duration", 'duration = "-2 h"\n' + MOTION, "duration", "out of range: '-2 h' must be > 0 s"),
    ("delta zero", 'duration = "1 h"\n' + MOTION + '[indexing]\nscheme = "flexible"\ndelta = 0\n',
     "indexing.delta", "out of range: 0 must be > 0"),
    ("zero rate", 'duration = "1 h"\n' + MOTION + '[indexing]\nscheme = "two_position"\nrate = "0 deg/s"\n',
     "indexing.rate", "out of range: '0 deg/s' must be > 0 deg/s"),
    ("record longer than run", 'duration = "10 s"\nrecord_every = "20 s"\n' + MOTION, "record_every",
     "longer than the duration"),
    ("alignment longer than run", 'duration = "100 s"\n' + MOTION + '[firmware]\nfine_time = "200 s"\n',
     "firmware.fine_time", "the alignment (200 s) is longer than the duration"),
    ("firmware refuses", 'duration = "1 h"\n' + MOTION + '[firmware]\ncoarse_time = "600 s"\n',
     "firmware.coarse_time", "the firmware refuses the configuration: PYINS_E_CONFIG_ALIGN_LONG"),
    ("manoeuvre too short", 'duration = "1 h"\n[motion]\nkind = "manoeuvre"\n', "motion.segments",
     "the manoeuvre lasts 1800 s, shorter than the duration 3600 s"),
    # types
    ("seed not an integer", 'duration = "1 h"\nseed = "one"\n' + MOTION, "seed",
     "must be an integer, got string 'one'"),
    ("bool as a string", 'duration = "1 h"\n' + MOTION + '[outputs]\nplots = "yes"\n', "outputs.plots",
     "must be true or false, got string 'yes'"),
    ("table as a string", 'duration = "1 h"\nmotion = "static"\n', "motion", "must be a table"),
    ("wrong length", 'duration = "1 h"\n' + MOTION + '[sensors]\naccel_bias = ["1 ug", "2 ug"]\n',
     "sensors.accel_bias", "a list of 3, got 2 values"),
    ("matrix diagonal", 'duration = "1 h"\n' + MOTION + '[sensors]\ngyro_misalignment = '
     '[["1 arcsec", 0, 0], [0, 0, 0], [0, 0, 0]]\n', "sensors.gyro_misalignment",
     "the diagonal [0][0] must be 0"),
    # names
    ("unknown preset", 'duration = "1 h"\n' + MOTION + '[sensors]\npreset = "seed004"\n', "sensors.preset",
     "unknown value 'seed004'; did you mean 'seed003'? (choose one of error_free, seed000"),
    ("unknown scheme", 'duration = "1 h"\n' + MOTION + '[indexing]\nscheme = "flexibel"\n', "indexing.scheme",
     "unknown value 'flexibel'; did you mean 'flexible'?"),
    ("unknown sums", 'duration = "1 h"\n' + MOTION + '[indexing]\nscheme = "flexible_derived"\nsums = "turns"\n',
     "indexing.sums", "unknown value 'turns'"),
    ("unknown motion kind", 'duration = "1 h"\n[motion]\nkind = "statik"\n', "motion.kind",
     "unknown value 'statik'; did you mean 'static'?"),
    ("unknown metric", 'duration = "1 h"\n' + MOTION + '[[paper.figures]]\nmetric = "horizontal_error"\n'
     'value = "1 nmi"\n', "paper.figures[0].metric", "unknown value 'horizontal_error'"),
    # consistency
    ("yaw and heading", 'duration = "1 h"\n' + MOTION + 'yaw = "1 deg"\nheading = "1 deg"\n', "motion.heading",
     "give either yaw or heading, not both"),
    ("missing motion", 'duration = "1 h"\n', "motion", "missing table [motion]"),
    ("missing duration", MOTION, "duration", "missing (required: ship time simulated)"),
    ("custom without steps", 'duration = "1 h"\n' + MOTION + '[indexing]\nscheme = "custom"\n'
     'rate = "6 deg/s"\nacceleration = "30 deg/s^2"\n', "indexing.steps", "missing (required with scheme"),
    # the firmware refuses a step beyond 8 turns (16 pi): the file's key says so, not the firmware's status
    ("step beyond 8 turns", 'duration = "1 h"\n' + MOTION + '[indexing]\nscheme = "custom"\nrate = "6 deg/s"\n'
     'acceleration = "30 deg/s^2"\n[[indexing.steps]]\nstop = "1 s"\nmove = "fixed"\nangle = "2881 deg"\n',
     "indexing.steps[0].angle", "must be >= -2880 deg and <= 2880 deg"),
    ("steps without custom", 'duration = "1 h"\n' + MOTION + '[indexing]\nscheme = "flexible"\n'
     '[[indexing.steps]]\nstop = "1 s"\nmove = "fixed"\nangle = "1 deg"\n', "indexing.steps",
     "steps are only used with scheme = 'custom'"),
    ("compare key", 'duration = "1 h"\n' + MOTION + '[compare]\nkey = "indexing.shceme"\nvalues = ["none"]\n',
     "compare.key", "'indexing.shceme' is not a key; did you mean 'indexing.scheme'?"),
    ("compare value", 'duration = "1 h"\n' + MOTION + '[compare]\nkey = "indexing.scheme"\n'
     'values = ["none", "flexibel"]\n', "compare.values[1]", "indexing.scheme: unknown value 'flexibel'"),
    ("compare labels", 'duration = "1 h"\n' + MOTION + '[compare]\nkey = "seed"\nvalues = [1, 2]\n'
     'labels = ["a"]\n', "compare.labels", "1 labels for 2 values"),
    ("unknown variant", 'duration = "1 h"\n' + MOTION + '[compare]\nkey = "seed"\nvalues = [1, 2]\n'
     '[[paper.figures]]\nmetric = "horizontal_error_max"\nvalue = "1 nmi"\nvariant = "seed = 3"\n',
     "paper.figures[0].variant", "unknown variant 'seed = 3'"),
    ("figure unit", 'duration = "1 h"\n' + MOTION + '[[paper.figures]]\nmetric = "horizontal_error_max"\n'
     'value = "1 deg"\n', "paper.figures[0].value", "it is a unit of angle, but a length is wanted"),
]


@pytest.mark.parametrize("text, key, reason", [m[1:] for m in MISTAKES], ids=[m[0] for m in MISTAKES])
def test_each_mistake_is_one_line_naming_file_key_and_reason(tmp_path, text, key, reason):
    path = tmp_path / "mine.toml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as exc:
        scenario.load(path)
    msg = str(exc.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}: {key}: "), msg
    assert reason in msg, msg
    assert isinstance(exc.value, ValueError) and exc.value.key == key


def test_malformed_toml_names_the_line(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text('duration = "1 h"\n[motion]\nkind = static\n')
    with pytest.raises(ScenarioError) as exc:
        scenario.load(path)
    msg = str(exc.value)
    assert msg.startswith(f"{path}: malformed TOML: ") and "line 3" in msg and "\n" not in msg


def test_unknown_builtin_or_missing_file():
    with pytest.raises(ScenarioError, match=r"^seed02_exp1: no such file or built-in scenario; "
                                            r"did you mean 'seed002_exp1'\?"):
        scenario.load("seed02_exp1")
    with pytest.raises(ScenarioError, match=r"^nowhere/x.toml: no such file"):
        scenario.load("nowhere/x.toml")


# ---------------------------------------------------------------------------
# Through the firmware
# ---------------------------------------------------------------------------
def test_smoke_builtin_run_equals_the_reproduce_tool_run():
    """The flexible run of seed002_exp1, shortened to 500 ticks, through
    fil.run_fil: bit-identical to the run tools/papers/reproduce_seed002.py starts."""
    fil = pytest.importorskip("pyins.fil")
    tool = _tool("reproduce_seed002")
    sc = scenario.load("seed002_exp1").with_overrides({"duration": "5 s", "record_every": "0.5 s"})
    run = list(sc.runs())[2]
    assert run.label == "flexible two-position" and run.duration_ticks == 500 and run.every == 50
    ours = run_scenario.run(run)
    vid, tool_run = tool.variants(1, {"duration": "5 s", "record_every": "0.5 s"})[2]
    assert vid == "4" and run_scenario.run(tool_run).outputs.tobytes() == ours.outputs.tobytes()
    m = sim.HeadingSwing.experiment(1)
    theirs = fil.run_fil(m, 500, config=dict(index_scheme=4, **seed002_initial_errors(m)),
                         errors=sim.preset("seed002"), seed=1, every=50)
    assert len(ours.outputs) == 10
    assert ours.outputs.tobytes() == theirs.outputs.tobytes()
    e = metrics.nav_errors(ours)
    assert np.all(np.isfinite(e.horizontal_m)) and e.horizontal_m[0] == pytest.approx(10 * math.sqrt(2), rel=1e-3)
