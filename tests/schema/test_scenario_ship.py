"""Scenario files of a ship at the pier: heave, surge and sway (sinusoids or a
wave spectrum) and lever arms in [motion], firmware.lever and
firmware.coarse_method; the moored built-ins against pyins.sim.moored and
tools/papers/moored_alignment.py; files without these keys unchanged (motion and
digest); one clear line per mistake; a short run through the firmware."""
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

from pyins import run_scenario, scenario, sim
from pyins.reference import earth
from pyins.scenario import ScenarioError
from pyins import units
from tools_loader import load_tool

ROOT = Path(__file__).resolve().parents[2]
DEG = units.DEG_TO_RAD
METHODS = {"triad": 0, "fit": 1}      # pyins_coarse_method
MOORED = ["moored_bad", "moored_general", "moored_ideal", "moored_spectrum"]
SEEDS_PAPERS = ["demo", "seed000_static", "seed000_swing", "seed001_fine5", "seed001_fine8",
                "seed002_exp1", "seed002_exp2", "seed003"]


def _tool(name):
    return load_tool(f"papers/{name}.py")


def assert_same_ship(a, b):
    """Same ShipAtSea: bit-identical IMU and reference-point states, lever arms."""
    assert type(a) is type(b) is sim.ShipAtSea and type(a.base) is type(b.base)
    t = np.array([0.0, 1.234, 60.0, 299.99])
    for fa, fb in ((a.state, b.state), (a.reference_state, b.reference_state)):
        sa, sb = fa(t), fb(t)
        for f in ("lat", "lon", "height", "vel_n", "acc_n", "euler", "euler_rate"):
            assert np.array_equal(getattr(sa, f), getattr(sb, f)), f
    assert np.array_equal(a.lever_b, b.lever_b) and np.array_equal(a.lever_p, b.lever_p)


def assert_same_errors(a, b):
    for f in fields(sim.SensorErrors):
        assert np.array_equal(getattr(a, f.name), getattr(b, f.name)), f.name


BASE = """
duration = "60 s"
[motion]
kind = "sea_state"
sea_state = "general"
heading = "240 deg"
"""


# ---------------------------------------------------------------------------
# Built-ins
# ---------------------------------------------------------------------------
def test_moored_builtins_match_sim_moored_and_the_tool():
    """The ship of pyins.sim.moored, the sensors of tools/papers/reproduce_seed000.py
    (tools/papers/moored_alignment.py uses both) and its seeds, TRIAD's 300-s alignment
    on a 2 s grid (tools/papers/moored_alignment.py's TRIAD run) for both methods."""
    tool = _tool("reproduce_seed000")
    for state in ("ideal", "general", "bad"):
        sc = scenario.load(f"moored_{state}")
        runs = list(sc.runs())
        assert [r.label for r in runs] == ["TRIAD (seed 000)", "FIT (moving base)"]
        m = sim.moored(state, tool.LAT, tool.LON, 0.0, -240.0 * DEG)
        for r, method in zip(runs, ("triad", "fit")):
            assert_same_ship(r.motion, m)
            assert_same_errors(r.errors, tool.sensors(seed=r.seed)[1])
            assert r.seed == 7 + 1000 * 240 + 0 and r.duration_ticks == 30_000
            # the configuration the firmware gets is the tool's (run_case), bit for bit
            ours = scenario.initial_config(r.motion, None, **r.config)
            theirs = scenario.initial_config(m, None, coarse_ticks=30_000, coarse_method=METHODS[method],
                                           coarse_output_every_ticks=200, euler_b_rad=[0.0, 0.0, 0.0])
            assert set(ours) - set(theirs) == {"index_scheme", "coarse_ratio"}
            assert ours["index_scheme"] == 0 and ours["coarse_ratio"] == 0.5
            for key, value in theirs.items():
                assert np.array_equal(np.asarray(ours[key]), np.asarray(value)), key
            assert np.array_equal(ours["lever_b_m"], sim.MOORED_SHIP["lever_b"])
        # the written-out linear motion is MOORED_SHIP's
        res = sc.resolved()["motion"]
        for axis in ("heave", "surge", "sway"):
            assert [(c["amplitude_m"], c["period_s"], c["phase_rad"]) for c in res[axis]] == \
                [tuple(c) for c in sim.MOORED_SHIP[axis]]
        assert sc.resolved()["firmware"]["lever"] == "configured"
        figs = {f["metric"] for f in sc.paper["figures"]}
        assert figs == {"level_error_vs_limit_final", "heading_error_vs_limit_final"}


def test_moored_spectrum_builtin_is_the_preset_sea():
    runs = list(scenario.load("moored_spectrum").runs())
    want = sim.named_sea_spectrum("moored_moderate", seed=0)
    general = next(scenario.load("moored_general").runs())
    for r in runs:
        assert isinstance(r.motion, sim.ShipAtSea)
        for axis in ("heave", "surge", "sway"):
            assert getattr(r.motion.linear, axis) == getattr(want, axis) and len(getattr(want, axis)) == 40
        assert np.array_equal(r.motion.lever_b, general.motion.lever_b)
        t = np.array([0.0, 17.3, 250.0])
        assert np.array_equal(r.motion.base.state(t).euler, general.motion.base.state(t).euler)


def test_at_anchor_builtin_is_sim_at_anchor_with_the_moored_ships_heave_and_lever():
    (r,) = scenario.load("at_anchor").runs()
    m = sim.at_anchor("general", 34.246 * DEG, 108.910 * DEG, 0.0, -240.0 * DEG, radius=50.0, period=2400.0,
                      swing=30.0 * DEG, heave=sim.MOORED_SHIP["heave"], lever_b=sim.MOORED_SHIP["lever_b"])
    assert_same_ship(r.motion, m)
    # the firmware is told the lever arm (lever = "configured")
    cfg = scenario.initial_config(r.motion, None, **r.config)
    assert np.array_equal(cfg["lever_b_m"], sim.MOORED_SHIP["lever_b"])


def test_at_anchor_adds_the_files_waves_to_its_arc_and_refuses_a_wide_swing(tmp_path):
    text = """
duration = "60 s"
[motion]
kind = "at_anchor"
sea_state = "bad"
heading = "90 deg"
radius = "80 m"
swing_period = "20 min"
swing_angle = "%s"
swing_phase = "45 deg"
sway = [{ amplitude = "0.3 m", period = "10 s", phase = "0 deg" }]
"""
    f = tmp_path / "anchor.toml"
    f.write_text(text % "60 deg")
    (r,) = scenario.load(f).runs()
    surge, sway = sim.anchor_linear(80.0, 1200.0, 60.0 * DEG, 45.0 * DEG)
    assert r.motion.linear.sway == tuple(sway) + ((0.3, 10.0, 0.0),)
    assert r.motion.linear.surge == tuple(surge) and r.motion.linear.heave == ()
    assert np.array_equal(r.motion.lever_b, np.zeros(3))       # no lever unless the file gives one
    f.write_text(text % "100 deg")
    with pytest.raises(ScenarioError, match="motion.swing_angle"):
        scenario.load(f)


def test_files_without_ship_keys_build_and_resolve_as_before():
    for name in SEEDS_PAPERS:
        sc = scenario.load(name)
        for res in [sc.resolved()] + sc.resolved().get("variants", []):
            assert not set(res["motion"]) & {"heave", "surge", "sway", "spectrum", "lever_b_m",
                                              "lever_p_m"}, name
            assert "lever" not in res["firmware"] and "coarse_method" not in res["firmware"], name
        for r in sc.runs():
            assert not isinstance(r.motion, sim.ShipAtSea), name
            assert not set(r.config) & {"lever_b_m", "lever_p_m", "coarse_method"}, name
    # the default written out changes nothing, digest included
    plain = scenario.loads(BASE)
    assert scenario.loads(BASE + '[firmware]\nlever = "configured"\n').digest() == plain.digest()
    assert isinstance(next(plain.runs()).motion, sim.Swing)


def test_any_ship_key_makes_a_ship_at_sea():
    lever = 'lever_b = ["0.5 m", "1.5 m", "1.2 m"]\n'
    (r,) = scenario.loads(BASE + lever).runs()
    assert isinstance(r.motion, sim.ShipAtSea) and r.motion.linear is None
    assert np.array_equal(r.motion.lever_b, [0.5, 1.5, 1.2])
    # an empty heave is still a ship, whose states are the base profile's bit for bit
    (r,) = scenario.loads(BASE + "heave = []\n").runs()
    (p,) = scenario.loads(BASE).runs()
    assert isinstance(r.motion, sim.ShipAtSea) and r.motion.linear.periods == ()
    t = np.array([0.0, 3.3, 59.0])
    for f in ("lat", "lon", "height", "vel_n", "euler"):
        assert np.array_equal(getattr(r.motion.state(t), f), getattr(p.motion.state(t), f)), f
    # one table is a one-sinusoid array: the same scenario, the same digest
    one = 'heave = { amplitude = "0.5 m", period = "8 s" }\n'
    arr = 'heave = [{ amplitude = "0.5 m", period = "8 s", phase = "0 deg" }]\n'
    assert scenario.loads(BASE + one).digest() == scenario.loads(BASE + arr).digest()
    # periods need not be whole ticks; phases in any angle unit
    (r,) = scenario.loads(BASE + 'sway = [{ amplitude = "30 cm", period = "7.777 s", phase = "90 deg" },'
                                 ' { amplitude = "-0.1 m", period = "3 s" }]\n').runs()
    assert r.motion.linear.sway == ((0.3, 7.777, np.pi / 2), (-0.1, 3.0, 0.0)) and r.motion.linear.heave == ()
    # a spectrum, written out
    (r,) = scenario.loads(BASE + 'spectrum = { hs = "1 m", tp = "6 s", kind = "pm", seed = 3, '
                                 'components = 12 }\n').runs()
    want = sim.sea_spectrum_motion(1.0, 6.0, spectrum="pm", seed=3, n_components=12)
    assert r.motion.linear.heave == want.heave and r.motion.linear.sway == want.sway
    res = scenario.loads(BASE + 'spectrum = { name = "open_rough", seed = 2 }\n').resolved()["motion"]
    assert res["spectrum"] == {"name": "open_rough", "hs_m": 3.0, "tp_s": 8.0, "kind": "jonswap",
                               "gamma": 1.55, "seed": 2, "components": 40}
    assert scenario.loads(BASE + 'spectrum = { hs = "1 m", tp = "6 s" }\n').resolved()[
        "motion"]["spectrum"]["gamma"] == 3.3
    # every fixed-position kind takes them
    for kind in ('kind = "static"', 'kind = "swing"\namplitude = "1 deg"\nfrequency = "0.1 Hz"',
                 'kind = "heading_swing"\nexperiment = 1'):
        (r,) = scenario.loads(f'duration = "60 s"\n[motion]\n{kind}\n{lever}').runs()
        assert isinstance(r.motion, sim.ShipAtSea)


def test_the_firmware_gets_the_reference_point_and_the_lever_as_told():
    ship = ('surge = [{ amplitude = "10 m", period = "30 s", phase = "90 deg" }]\n'
            'heave = [{ amplitude = "1 m", period = "8 s" }]\nlever_b = ["3 m", "20 m", "5 m"]\n')
    errs = '[initial_errors]\nnorth = "5 m"\nvelocity = ["0.1 m/s", 0, 0]\nheading = "1 deg"\n'
    (r,) = scenario.loads(BASE + ship + errs).runs()
    ref = r.motion.reference_state(np.array([0.0]))
    imu = r.motion.state(np.array([0.0]))
    rm, _ = earth.principal_radii(np.sin(ref.lat[0]))
    assert r.config["lat_rad"] == ref.lat[0] + 5.0 / rm != imu.lat[0] + 5.0 / rm
    assert np.array_equal(r.config["vel_n_mps"], ref.vel_n[0] + np.array([0.1, 0.0, 0.0]))
    assert not np.allclose(ref.vel_n[0], imu.vel_n[0])          # the lever arm turns with the ship
    assert "lever_b_m" not in r.config                           # scenario.initial_config adds the motion's
    full = scenario.initial_config(r.motion, None, **r.config)
    assert np.array_equal(full["lever_b_m"], [3.0, 20.0, 5.0]) and np.array_equal(full["lever_p_m"], [0, 0, 0])
    assert full["height_m"] == ref.height[0] and full["lon_rad"] == ref.lon[0]
    # unknown: the firmware is told no lever arm, the plant keeps it
    (u,) = scenario.loads(BASE + ship + errs + '[firmware]\nlever = "unknown"\ncoarse_method = "fit"\n').runs()
    assert u.config["lever_b_m"] == [0.0] * 3 and u.config["lever_p_m"] == [0.0] * 3
    assert u.config["coarse_method"] == 1 and np.array_equal(u.motion.lever_b, [3.0, 20.0, 5.0])
    assert np.array_equal(scenario.initial_config(u.motion, None, **u.config)["lever_b_m"], [0, 0, 0])
    (t,) = scenario.loads(BASE + '[firmware]\ncoarse_method = "triad"\n').runs()
    assert t.config["coarse_method"] == 0
    # compare and overrides reach the new keys
    sc = scenario.load("moored_general")
    assert [r.config["coarse_method"] for r in sc.runs()] == [0, 1]
    sc2 = sc.with_overrides({"firmware.lever": "unknown", "motion.heave": {"amplitude": "2 m", "period": "8 s"}})
    r2 = next(sc2.runs())
    assert r2.config["lever_b_m"] == [0.0] * 3 and r2.motion.linear.heave == ((2.0, 8.0, 0.0),)
    assert sc2.digest() != sc.digest()


def test_docs_name_the_ship_keys():
    doc = (ROOT / "docs" / "scenarios.md").read_text()
    for keys in (scenario.SHIP_KEYS, scenario.COMPONENT_KEYS, scenario.SPECTRUM_KEYS):
        for name in keys:
            assert f"`{name}`" in doc, name
    for name in [*MOORED, *sim.SEA_STATE_SPECTRA, "configured", "unknown", "triad", "fit"]:
        assert name in doc, name


# ---------------------------------------------------------------------------
# One line per mistake
# ---------------------------------------------------------------------------
MISTAKES = [
    ("unknown sinusoid key", 'heave = [{ amplitud = "1 m", period = "8 s" }]\n', "motion.heave[0].amplitud",
     "unknown key; did you mean 'amplitude'?"),
    ("negative period", 'heave = [{ amplitude = "1 m", period = "-8 s" }]\n', "motion.heave[0].period",
     "out of range: '-8 s' must be > 0 s"),
    ("zero period", 'surge = { amplitude = "1 m", period = "0 s" }\n', "motion.surge.period",
     "out of range: '0 s' must be > 0 s"),
    ("missing period", 'sway = [{ amplitude = "1 m" }]\n', "motion.sway[0].period", "missing (required: period"),
    ("amplitude too large", 'sway = [{ amplitude = "150 m", period = "8 s" }]\n', "motion.sway[0].amplitude",
     "out of range: '150 m' must be >= -100 m and <= 100 m"),
    ("amplitude unit", 'heave = [{ amplitude = "1 deg", period = "8 s" }]\n', "motion.heave[0].amplitude",
     "it is a unit of angle, but a length is wanted"),
    ("heave not tables", 'heave = "1 m"\n', "motion.heave", "must be an array of tables"),
    ("lever too long", 'lever_b = ["100 m", "100 m", "100 m"]\n', "motion.lever_b",
     "out of range: the lever arm is 173.205 m long; it must be <= 100 m"),
    ("lever component", 'lever_b = ["150 m", "0 m", "0 m"]\n', "motion.lever_b[0]",
     "out of range: '150 m' must be >= -100 m and <= 100 m"),
    ("lever not a list", 'lever_b = "1 m"\n', "motion.lever_b", "must be a list of 3 lengths"),
    ("lever of 2", 'lever_b = ["1 m", "1 m"]\n', "motion.lever_b", "a list of 3 lengths [x starboard, y bow, z up], got 2 values"),
    ("lever_p and the plant", 'lever_p = ["0.1 m", "0 m", "0 m"]\n', "motion.lever_p",
     "lever_p is not supported by the compiled FIL plant yet"),
    ("spectrum and heave", 'heave = [{ amplitude = "1 m", period = "8 s" }]\n'
     'spectrum = { name = "moored_moderate" }\n', "motion.spectrum",
     "give either a spectrum or heave/surge/sway sinusoids, not both (the file gives heave too)"),
    ("hs zero", 'spectrum = { hs = "0 m", tp = "8 s" }\n', "motion.spectrum.hs",
     "out of range: '0 m' must be > 0 m"),
    ("hs negative", 'spectrum = { hs = "-1 m", tp = "8 s" }\n', "motion.spectrum.hs", "out of range"),
    ("hs missing", 'spectrum = { tp = "8 s" }\n', "motion.spectrum.hs",
     "missing (required unless 'name' is given"),
    ("tp zero", 'spectrum = { hs = "1 m", tp = "0 s" }\n', "motion.spectrum.tp", "out of range"),
    ("tp too short", 'spectrum = { hs = "1 m", tp = "0.001 s" }\n', "motion.spectrum",
     "too short for periods rounded to 0.01 s"),
    ("unknown preset sea", 'spectrum = { name = "moored_modrate" }\n', "motion.spectrum.name",
     "unknown value 'moored_modrate'; did you mean 'moored_moderate'?"),
    ("gamma with pm", 'spectrum = { hs = "1 m", tp = "8 s", kind = "pm", gamma = 2 }\n', "motion.spectrum.gamma",
     "not used with kind = 'pm'"),
    ("gamma range", 'spectrum = { hs = "1 m", tp = "8 s", gamma = 9 }\n', "motion.spectrum.gamma",
     "out of range: 9 must be >= 1 and <= 7"),
    ("unknown spectrum key", 'spectrum = { hs = "1 m", tp = "8 s", sead = 2 }\n', "motion.spectrum.sead",
     "unknown key; did you mean 'seed'?"),
    ("spectrum not a table", 'spectrum = "moored_moderate"\n', "motion.spectrum", "must be a table"),
    ("unknown ship key", 'heav = []\n', "motion.heav", "unknown key; did you mean 'heave'?"),
    ("unknown lever value", '[firmware]\nlever = "unkown"\n', "firmware.lever",
     "unknown value 'unkown'; did you mean 'unknown'?"),
    ("unknown coarse method", '[firmware]\ncoarse_method = "fitt"\n', "firmware.coarse_method",
     "unknown value 'fitt'; did you mean 'fit'?"),
    ("FIT output too early", '[firmware]\ninitial_attitude = "zero"\ncoarse_time = "60 s"\n'
     'coarse_output_every = "5 s"\ncoarse_method = "fit"\n', "firmware.coarse_first_output",
     "the firmware refuses the configuration: PYINS_E_CONFIG_ALIGN_EARLY"),
    ("coarse history", '[firmware]\ninitial_attitude = "zero"\ncoarse_time = "60 s"\n'
     'coarse_output_every = "0.1 s"\n', "firmware.coarse_time",
     "the firmware refuses the configuration: PYINS_E_CONFIG_ALIGN_LONG"),
]


@pytest.mark.parametrize("text, key, reason", [m[1:] for m in MISTAKES], ids=[m[0] for m in MISTAKES])
def test_each_ship_mistake_is_one_line_naming_file_key_and_reason(tmp_path, text, key, reason):
    path = tmp_path / "mine.toml"
    path.write_text(BASE + text)
    with pytest.raises(ScenarioError) as exc:
        scenario.load(path)
    msg = str(exc.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}: {key}: "), msg
    assert reason in msg, msg
    assert exc.value.key == key


@pytest.mark.parametrize("name", ["heave", "spectrum", "lever_b", "lever_p"])
def test_a_manoeuvre_refuses_the_ship_keys(name):
    value = {"heave": '[{ amplitude = "1 m", period = "8 s" }]', "spectrum": '{ name = "moored_moderate" }',
             "lever_b": '["1 m", "0 m", "0 m"]', "lever_p": '["1 m", "0 m", "0 m"]'}[name]
    with pytest.raises(ScenarioError) as exc:
        scenario.loads(f'duration = "60 s"\n[motion]\nkind = "manoeuvre"\n{name} = {value}\n', source="m.toml")
    assert str(exc.value) == (f"m.toml: motion.{name}: not used with kind 'manoeuvre': heave, surge, sway, "
                              f"spectrum and lever arms need a fixed-position kind (static, swing, sea_state, "
                              f"heading_swing, at_anchor)")


def test_compare_and_overrides_check_the_ship_keys():
    sc = scenario.load("moored_general")
    with pytest.raises(ScenarioError, match=r"\(with overrides\): motion.lever_b: out of range: the lever arm"):
        sc.with_overrides({"motion.lever_b": ["90 m", "90 m", "0 m"]})
    with pytest.raises(ScenarioError, match=r"compare.values\[1\]: firmware.coarse_method: unknown value 'fot'"):
        scenario.loads(BASE + '[compare]\nkey = "firmware.coarse_method"\nvalues = ["triad", "fot"]\n')


# ---------------------------------------------------------------------------
# Through the firmware
# ---------------------------------------------------------------------------
def test_smoke_moored_run_equals_a_direct_fil_run():
    """moored_general shortened to 30 s (FIT and lever unknown), through
    fil.run_fil: bit-identical to the run of sim.moored with that
    configuration; the unknown lever arm is what the firmware is told."""
    fil = pytest.importorskip("pyins.fil")
    tool = _tool("reproduce_seed000")
    short = {"duration": "30 s", "firmware.coarse_time": "30 s", "record_every": "2 s"}
    sc = scenario.load("moored_general").with_overrides(short)
    m = sim.moored("general", tool.LAT, tool.LON, 0.0, -240.0 * DEG)
    cfg = dict(coarse_ticks=3000, coarse_method=1, coarse_output_every_ticks=200, coarse_ratio=0.5,
               euler_b_rad=[0.0, 0.0, 0.0], index_scheme=0)
    fit = list(sc.runs())[1]
    ours = run_scenario.run(fit)
    theirs = fil.run_fil(m, 3000, config=cfg, errors=tool.sensors(seed=240007)[1], seed=240007, every=200)
    assert len(ours.outputs) == 15 and ours.outputs.tobytes() == theirs.outputs.tobytes()
    # the truth is the reference point's: zero lever arm -> the same position, another velocity
    assert np.array_equal(ours.truth.lat, m.reference_state(ours.outputs["tick"] * 0.01).lat)
    unknown = run_scenario.run(list(sc.with_overrides({"firmware.lever": "unknown"}).runs())[1])
    theirs_u = fil.run_fil(m, 3000, config=dict(cfg, lever_b_m=np.zeros(3), lever_p_m=np.zeros(3)),
                           errors=tool.sensors(seed=240007)[1], seed=240007, every=200)
    assert unknown.outputs.tobytes() == theirs_u.outputs.tobytes() != ours.outputs.tobytes()
