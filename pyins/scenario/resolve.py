"""Resolving a scenario file: every table checked and turned into plain
SI values (a JSON-serialisable dict whose keys carry their unit:
``lat_rad``, ``duration_s``; None = not set, the firmware's default).

`_resolve` does one variant (everything but [compare] and [paper], which
concern the scenario as a whole), table by table in the order of the file's
reference (docs/scenarios.md); `_resolve_paper` the [paper] figures;
`_set_key` and `_check_key_path` the dotted key paths of [compare] and
overrides.
"""
import difflib
import math
import re

import numpy as np

from pyins import analysis, sim
from pyins.scenario.build import _build_motion, _is_ship, _spectrum_motion
from pyins.scenario.schema import (COMPONENT_KEYS, FIGURE_KEYS, FIRMWARE_KEYS, INDEX_SCHEMES,
                                   INDEXING_KEYS, INITIAL_ERROR_KEYS, METRICS, MOTION_COMMON,
                                   MOTION_KINDS, OUTPUT_KEYS, PAPER_KEYS, SCHEMA_VERSION, SEGMENT_KEYS,
                                   SENSOR_KEYS, SHIP_KEYS, SPECTRUM_KEYS, STEP_KEYS, TABLE_NAMES, TABLES,
                                   TOP_KEYS, TURNTABLE_KEYS, _FIXED_KINDS, _LINEAR_AXES, _SUFFIX,
                                   REFERENCE_TABLES, WINDOW_KEYS)
from pyins.scenario.values import (_array_of_tables, _check_keys, _convert, _join, _need_table, _read,
                                   _si, _suggest, _type_name)
from pyins.sim import motion as sim_motion
from pyins.sim import ship as sim_ship
from pyins.sim import turntable
from pyins.units import DEG_TO_RAD, DT, ScenarioError, parse_quantity, split_quantity


# ---------------------------------------------------------------------------
# 1. [motion] and its ship keys
# ---------------------------------------------------------------------------
def _resolve_motion(table, duration_s):
    path = "motion"
    _need_table(table, path)
    if "kind" not in table:
        raise ScenarioError("missing (required: motion profile, one of "
                            f"{', '.join(MOTION_COMMON['kind'].choices)})", "motion.kind")
    kind = _convert(table["kind"], MOTION_COMMON["kind"], "motion.kind")
    if kind not in _FIXED_KINDS:
        for name in SHIP_KEYS:
            if name in table:
                raise ScenarioError(f"not used with kind {kind!r}: heave, surge, sway, spectrum and "
                                    f"lever arms need a fixed-position kind ({', '.join(_FIXED_KINDS)})",
                                    f"motion.{name}")
    keys = dict(MOTION_COMMON)
    keys.update(MOTION_KINDS[kind])
    if kind == "heading_swing":
        exp = table.get("experiment")
        if exp is not None:
            exp = _convert(exp, keys["experiment"], "motion.experiment")
            a_deg, period = sim_motion.SEED002_EXPERIMENTS[exp]
            defaults = {"lat": sim_motion.SEED002_LAT, "lon": sim_motion.SEED002_LON,
                        "height": sim_motion.SEED002_HEIGHT, "pitch": sim_motion.SEED002_PITCH,
                        "roll": sim_motion.SEED002_ROLL, "rate_amplitude": a_deg * DEG_TO_RAD,
                        "period": period}
            if "heading" not in table:
                defaults["yaw"] = sim_motion.SEED002_YAW
        else:
            defaults = {}
            for name in ("rate_amplitude", "period"):
                if name not in table:
                    raise ScenarioError(f"missing (required unless 'experiment' is given: "
                                        f"{keys[name].doc})", f"motion.{name}")
    v = _read(table, path, keys, f" of motion kind {kind!r}")
    if kind == "heading_swing":
        for name, value in defaults.items():       # SI already: exactly the seed 002 constants
            if name not in table:
                v[name] = value
    if "heading" in table:
        if "yaw" in table:
            raise ScenarioError("give either yaw or heading, not both", "motion.heading")
        v["yaw"] = -v["heading"]
    del v["heading"]
    if kind == "voyage" and "yaw" not in table and "heading" not in table:
        v["yaw"] = None           # the route's own initial course
    ship = {name: v.pop(name) for name in SHIP_KEYS if name in keys}
    ship = {name: value for name, value in ship.items() if name in table}
    res = _si(v, keys)
    res.update(_resolve_ship(table, ship))
    if any(res.get("lever_p_m", ())):
        try:        # what pyins.fil.run_fil will ask of the motion
            sim.node_rates(_build_motion(res), np.arange(1), dt=DT)
        except ValueError as exc:
            raise ScenarioError(str(exc), "motion.lever_p") from None
    if kind == "voyage":
        res["duration_s"] = duration_s      # the route is cut there (a longer one extends it)
        # the chosen track's keys only when given: a route's file keeps its digest
        if res["speed_mps"] is None:
            del res["speed_mps"]
        if v["segments"] == "route":
            del res["segments"]
        else:
            if v["segments"] == "default":
                raise ScenarioError("must be 'route' or an array of legs, got 'default'", "motion.segments")
            res["segments"] = _resolve_segments(v["segments"])
            length = _build_motion(res).duration
            if length + 1e-9 < duration_s:
                raise ScenarioError(f"the legs last {length:g} s, shorter than the duration "
                                    f"{duration_s:g} s", "motion.segments")
        if res["current_mps"][2] != 0.0:
            raise ScenarioError("the current is horizontal: give [E, N, 0] (its up component must be 0)",
                                "motion.current")
    if kind == "manoeuvre":
        res["segments"] = _resolve_segments(v["segments"])
        length = _build_motion(res).duration
        if length + 1e-9 < duration_s:
            raise ScenarioError(f"the manoeuvre lasts {length:g} s, shorter than the duration "
                                f"{duration_s:g} s", "motion.segments")
    return res


def _resolve_components(raw, where):
    """heave/surge/sway: an array of {amplitude, period, phase} (or one table)."""
    if isinstance(raw, dict):
        tables, names = [raw], [where]
    else:
        tables = _array_of_tables(raw, where, 0, 1000)
        names = [f"{where}[{i}]" for i in range(len(tables))]
    return [_si(_read(t, p, COMPONENT_KEYS), COMPONENT_KEYS) for t, p in zip(tables, names)]


def _resolve_spectrum(raw):
    where = "motion.spectrum"
    _need_table(raw, where)
    v = _read(raw, where, SPECTRUM_KEYS)
    if v["name"] is not None:
        preset = sim.SEA_STATE_SPECTRA[v["name"]]
        for name in ("hs", "tp", "gamma"):
            if v[name] is None:
                v[name] = float(preset[name])
    else:
        for name in ("hs", "tp"):
            if v[name] is None:
                raise ScenarioError(f"missing (required unless 'name' is given: "
                                    f"{SPECTRUM_KEYS[name].doc.split(' (')[0]})", f"{where}.{name}")
    if v["kind"] == "pm":
        if "gamma" in raw:
            raise ScenarioError("not used with kind = 'pm' (the Pierson-Moskowitz spectrum has no "
                                "peak enhancement)", f"{where}.gamma")
        v["gamma"] = None
    elif v["gamma"] is None:
        v["gamma"] = 3.3
    res = _si(v, SPECTRUM_KEYS)
    try:
        _spectrum_motion(res)
    except ValueError as exc:
        raise ScenarioError(str(exc), where) from None
    return res


def _spectrum_motion(sp):
    return sim.sea_spectrum_motion(sp["hs_m"], sp["tp_s"], spectrum=sp["kind"],
                                   gamma=sp["gamma"] if sp["gamma"] is not None else 1.0,
                                   seed=sp["seed"], n_components=sp["components"])


def _resolve_ship(table, ship):
    """The resolved ship keys (only those the file gives: a file without them
    resolves, and digests, exactly as before they existed)."""
    out = {}
    for name in _LINEAR_AXES:
        if name in ship:
            out[name] = _resolve_components(ship[name], f"motion.{name}")
    if "spectrum" in ship:
        given = [name for name in _LINEAR_AXES if name in ship]
        if given:
            raise ScenarioError(f"give either a spectrum or heave/surge/sway sinusoids, not both "
                                f"(the file gives {', '.join(given)} too)", "motion.spectrum")
        out["spectrum"] = _resolve_spectrum(ship["spectrum"])
    for name in ("lever_b", "lever_p"):
        if name in ship:
            where = f"motion.{name}"
            if not isinstance(table[name], list):
                raise ScenarioError(f"must be a list of 3 lengths [x starboard, y bow, z up], got "
                                    f"{_type_name(table[name])} {table[name]!r}", where)
            r = [float(x) for x in ship[name]]
            length = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
            if length > sim_ship.MAX_METRES:
                raise ScenarioError(f"out of range: the lever arm is {length:g} m long; it must be "
                                    f"<= {sim_ship.MAX_METRES:g} m", where)
            out[name + "_m"] = r
    return out


def _resolve_segments(raw):
    where = "motion.segments"
    if raw == "default":
        return "default"
    if isinstance(raw, str):
        raise ScenarioError(f"must be 'default' or an array of legs, got {raw!r}", where)
    legs = []
    for i, leg in enumerate(_array_of_tables(raw, where, 1, 10_000)):
        p = f"{where}[{i}]"
        v = _read(leg, p, SEGMENT_KEYS)
        if v["kind"] in ("accelerate", "decelerate"):
            if v["speed"] is None:
                raise ScenarioError(f"missing (required for {v['kind']!r}: target speed)", f"{p}.speed")
            if v["angle"] is not None:
                raise ScenarioError(f"not used by an {v['kind']!r} leg", f"{p}.angle")
            value = v["speed"]
        elif v["kind"] == "turn":
            if v["angle"] is None:
                raise ScenarioError("missing (required for 'turn': yaw change)", f"{p}.angle")
            if v["speed"] is not None:
                raise ScenarioError("not used by a 'turn' leg", f"{p}.speed")
            value = v["angle"]
        else:
            for name in ("speed", "angle"):
                if v[name] is not None:
                    raise ScenarioError("not used by a 'cruise' leg", f"{p}.{name}")
            value = 0.0
        legs.append({"kind": v["kind"], "duration_s": v["duration"], "value": value})
    return legs


# ---------------------------------------------------------------------------
# 2. [sensors], [turntable], [indexing], [firmware], [initial_errors], [paper]
# ---------------------------------------------------------------------------
def _resolve_sensors(table):
    _need_table(table, "sensors")
    v = _read(table, "sensors", SENSOR_KEYS)
    base = sim.preset(v["preset"])
    out = {"preset": v["preset"]}
    for name, key in SENSOR_KEYS.items():
        if name == "preset":
            continue
        value = v[name] if v[name] is not None else getattr(base, name)
        out[name + _SUFFIX[key.kind]] = np.asarray(value, dtype=float).tolist()
    return out


def _resolve_turntable(table, duration_s):
    _need_table(table, "turntable")
    v = _read(table, "turntable", TURNTABLE_KEYS)
    d = turntable.TableConfig()
    for name, field in (("rate_max", "rate_max_rad_s"), ("accel_max", "accel_max_rad_s2"),
                        ("encoder_lsb", "encoder_lsb_rad")):
        if v[name] is None:
            v[name] = getattr(d, field)
    if v["fault"] == "jump" and v["jump"] == 0.0:
        raise ScenarioError("the 'jump' fault needs a non-zero jump angle", "turntable.jump")
    return _si(v, TURNTABLE_KEYS)


def _resolve_indexing(table):
    _need_table(table, "indexing")
    v = _read(table, "indexing", INDEXING_KEYS)
    custom = v["scheme"] == "custom"
    if v["scheme"] == "seed003":
        v["scheme"] = "single_position"
    steps = None
    if v["steps"] is not None:
        if not custom:
            raise ScenarioError(f"steps are only used with scheme = 'custom' (the scheme is "
                                f"{v['scheme']!r})", "indexing.steps")
        steps = []
        for i, step in enumerate(_array_of_tables(v["steps"], "indexing.steps", 1, 8)):
            s = _read(step, f"indexing.steps[{i}]", STEP_KEYS)
            if s["angle"] == 0.0:
                raise ScenarioError("out of range: the angle of a step must not be zero",
                                    f"indexing.steps[{i}].angle")
            steps.append({"stop_s": s["stop"], "move": s["move"], "angle_rad": s["angle"]})
    if custom:
        if steps is None:
            raise ScenarioError("missing (required with scheme = 'custom': 1 to 8 steps)",
                                "indexing.steps")
        for name in ("rate", "acceleration"):
            if v[name] is None:
                raise ScenarioError("missing (required with scheme = 'custom')", f"indexing.{name}")
        if v["delta"] is None and any(s["move"] != "fixed" for s in steps):
            raise ScenarioError("missing (required with flexible steps)", "indexing.delta")
        if v["stop"] is not None:
            raise ScenarioError("not used with scheme = 'custom' (each step has its own stop)",
                                "indexing.stop")
    out = _si(v, INDEXING_KEYS)
    out["scheme_number"] = INDEX_SCHEMES[v["scheme"]]
    out["steps"] = steps
    return out


def _resolve_firmware(table, duration_s):
    _need_table(table, "firmware")
    v = _read(table, "firmware", FIRMWARE_KEYS)
    align = (v["coarse_time"] or 0.0) + (v["fine_time"] or 0.0)
    if align > duration_s + 1e-9:
        key = "firmware.fine_time" if v["fine_time"] else "firmware.coarse_time"
        raise ScenarioError(f"out of range: the alignment ({align:g} s) is longer than the duration "
                            f"({duration_s:g} s)", key)
    swing = v.pop("fine_site_swing")
    if swing is not None:
        v["fine_site_accel"] = _site_accel_of_swing(swing, v["fine_site_accel"])
    return _si(v, FIRMWARE_KEYS)


#: fine_site_accel's upper limit [m/s^2/sqrt(Hz)] (schema: 10 mg/sqrt(Hz))
_SITE_ACCEL_MAX = 10e-3 * 9.80665


def _site_accel_of_swing(raw, site_accel):
    """fine_site_swing = [radius, period, half angle] -> the density q
    that covers the swing (`analysis.site_accel_for_swing`)."""
    where = "firmware.fine_site_swing"
    if site_accel is not None:
        raise ScenarioError("give fine_site_swing or fine_site_accel, not both (the swing sets the "
                            "density)", where)
    if len(raw) != 3:
        raise ScenarioError(f"must be [radius, period, half angle], got {len(raw)} values", where)
    radius = parse_quantity(raw[0], "length", where=f"{where}[0]")
    period = parse_quantity(raw[1], "time", where=f"{where}[1]")
    half = parse_quantity(raw[2], "angle", where=f"{where}[2]")
    if not 0.0 < radius <= 1000.0:
        raise ScenarioError(f"out of range: radius {radius:g} m, must be within (0, 1000] m", f"{where}[0]")
    if not 60.0 <= period <= 86400.0:
        raise ScenarioError(f"out of range: period {period:g} s, must be within 1 min .. 1 d", f"{where}[1]")
    if not 0.0 < half <= math.pi / 2.0:
        raise ScenarioError(f"out of range: half angle {half / DEG_TO_RAD:g} deg, must be within (0, 90] deg",
                            f"{where}[2]")
    q = analysis.site_accel_for_swing(radius, period, half)
    if q > _SITE_ACCEL_MAX:
        raise ScenarioError(f"this swing needs a site density of {q / 9.80665e-6:.0f} ug/sqrt(Hz), beyond the "
                            "firmware's 10 mg/sqrt(Hz): no alignment without a reference can cover it",
                            where)
    return q


def _windows(raw, where, duration_s):
    out = []
    for i, w in enumerate(_array_of_tables(raw or [], where, 0, 10_000)):
        p = f"{where}[{i}]"
        v = _read(w, p, WINDOW_KEYS)
        if not v["end"] > v["start"]:
            raise ScenarioError(f"end ({v['end']:g} s) must be after start ({v['start']:g} s)", f"{p}.end")
        out.append([v["start"], v["end"]])
    return out


#: a reference sensor's mounting vectors: (name, the firmware's limit on its length, unit)
_MOUNTINGS = {"dvl": (("misalignment", math.pi, "deg"), ("misalignment_told", math.pi, "deg"),
                      ("lever", sim_ship.MAX_METRES, "m")),
              "gnss": (("lever", sim_ship.MAX_METRES, "m"), ("lever_told", sim_ship.MAX_METRES, "m"))}


def _check_mounting(sub, v, path, vectors):
    """A sensor's mounting vectors ([references.dvl]'s rotations and arm,
    [references.gnss]'s antenna arm): lists of three (one value for all
    three axes is no rotation or arm anyone means), a rotation at most 180
    deg (dvl_align_rad's limit), an arm at most 100 m (the firmware's)."""
    for name, _, _ in vectors:
        if name in sub and not isinstance(sub[name], list):
            raise ScenarioError(f"must be a list of 3 values [x starboard, y bow, z up], got "
                                f"{_type_name(sub[name])} {sub[name]!r}", f"{path}.{name}")
    for name, limit, unit in vectors:
        if v[name] is None:
            continue
        length = math.sqrt(sum(x * x for x in v[name]))
        if length > limit:
            shown = math.degrees(length) if unit == "deg" else length
            bound = 180.0 if unit == "deg" else limit
            raise ScenarioError(f"out of range: {'the rotation is' if unit == 'deg' else 'the lever arm is'} "
                                f"{shown:g} {unit} long; it must be <= {bound:g} {unit}", f"{path}.{name}")


def _resolve_references(table, duration_s, firmware):
    """[references]: {gnss: {...}, zero_velocity: {...}}, each only when
    given (SI, the windows as [start_s, end_s] pairs)."""
    _need_table(table, "references")
    _check_keys(table, "references", list(REFERENCE_TABLES))
    if table and firmware.get("nav_mode") == "undamped":
        raise ScenarioError("the firmware takes no references with nav_mode = 'undamped'",
                            "firmware.nav_mode")
    out = {}
    for name, keys in REFERENCE_TABLES.items():
        if name not in table:
            continue
        path = f"references.{name}"
        sub = _need_table(table[name], path)
        v = _read(sub, path, keys)
        for rate_key in ("rate",):
            step = 1.0 / (v[rate_key] * DT)
            if abs(step - round(step)) > 1e-6 or round(step) < 1:
                raise ScenarioError(f"{v[rate_key]:g} Hz: 1 / rate must be a whole number of ticks "
                                    f"({DT:g} s)", f"{path}.{rate_key}")
        if name == "gnss":
            if not (v["position"] or v["velocity"]):
                raise ScenarioError("position and velocity are both false: the receiver gives no fixes",
                                    f"{path}.position")
            if v["position"] and firmware.get("nav_mode") == "damped":
                raise ScenarioError("nav_mode = 'damped' takes no GNSS position (its position is dead "
                                    "reckoning; a fix would reset it, which is 'integrated'): set "
                                    "references.gnss.position = false", f"{path}.position")
            v["outages"] = _windows(v["outages"], f"{path}.outages", duration_s)
            v["frozen"] = _windows(v["frozen"], f"{path}.frozen", duration_s)
            if v["outage_every"] and v["outage_length"] >= v["outage_every"]:
                raise ScenarioError(f"{v['outage_length']:g} s: an outage must be shorter than the "
                                    f"interval outage_every ({v['outage_every']:g} s)",
                                    f"{path}.outage_length")
        if name in _MOUNTINGS:
            _check_mounting(sub, v, path, _MOUNTINGS[name])
        keys_si = {k: key for k, key in keys.items() if k not in ("outages", "frozen")}
        res = _si({k: v[k] for k in keys_si}, keys_si)
        if name == "gnss":
            res["outages"], res["frozen"] = v["outages"], v["frozen"]
        out[name] = res
    return out


def _resolve_initial_errors(table, firmware):
    _need_table(table, "initial_errors")
    v = _read(table, "initial_errors", INITIAL_ERROR_KEYS)
    if v["heading"] is not None:
        if v["yaw"] is not None:
            raise ScenarioError("give either yaw or heading, not both", "initial_errors.heading")
        v["yaw"] = -v["heading"]
    del v["heading"]
    euler_keys = [k for k in ("pitch", "roll", "yaw") if v[k] is not None]
    if v["phi"] is not None and euler_keys:
        raise ScenarioError("give the attitude error either as phi or as pitch/roll/yaw, not both",
                            "initial_errors.phi")
    if firmware["initial_attitude"] == "zero" and (v["phi"] is not None or euler_keys):
        key = "initial_errors.phi" if v["phi"] is not None else f"initial_errors.{euler_keys[0]}"
        raise ScenarioError("an attitude error cannot be applied with firmware.initial_attitude = "
                            "'zero'", key)
    keys = dict(INITIAL_ERROR_KEYS)
    del keys["heading"]
    return _si(v, keys)


def _resolve_paper(table, labels):
    _need_table(table, "paper")
    v = _read(table, "paper", PAPER_KEYS)
    figures = []
    for i, fig in enumerate(_array_of_tables(v["figures"] or [], "paper.figures", 0, 1000)):
        p = f"paper.figures[{i}]"
        f = _read(fig, p, FIGURE_KEYS)
        dim = METRICS[f["metric"]][0]
        value_si = parse_quantity(f["value"], dim, where=f"{p}.value")
        number, unit = split_quantity(f["value"]) if isinstance(f["value"], str) else (0.0, "")
        if f["variant"] is not None and not labels:
            raise ScenarioError("a variant is only named with [compare]", f"{p}.variant")
        if f["variant"] is not None and f["variant"] not in labels:
            raise ScenarioError(f"unknown variant {f['variant']!r} (the runs are labelled "
                                f"{', '.join(map(repr, labels))})", f"{p}.variant")
        figures.append({"metric": f["metric"], "relation": f["relation"], "value": number,
                        "unit": unit, "value_si": value_si, "variant": f["variant"],
                        "note": f["note"]})
    return {"citation": v["citation"], "note": v["note"], "figures": figures}


# ---------------------------------------------------------------------------
# 3. One variant, whole
# ---------------------------------------------------------------------------
def _resolve(data, stem):
    """The resolved form (a plain dict, SI) of one variant: everything but
    [compare] and [paper], which concern the scenario as a whole."""
    _check_keys(data, "", list(TOP_KEYS) + list(TABLE_NAMES))
    top = _read({k: v for k, v in data.items() if k in TOP_KEYS}, "", TOP_KEYS)
    name = top["name"] if top["name"] is not None else stem
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        raise ScenarioError(f"{name!r} may hold only letters, digits, '_', '.' and '-'", "name")
    duration_s = top["duration"]
    if top["record_every"] > duration_s:
        raise ScenarioError(f"out of range: {top['record_every']:g} s is longer than the duration "
                            f"({duration_s:g} s)", "record_every")
    if "motion" not in data:
        raise ScenarioError("missing table [motion] (required: the ship's motion)", "motion")
    motion = _resolve_motion(data["motion"], duration_s)
    firmware = _resolve_firmware(data.get("firmware", {}), duration_s)
    # keys newer than schema 1's files are resolved only when they say
    # something, so that the older files keep their digests
    if firmware["coarse_method"] is None:
        del firmware["coarse_method"]
    if firmware["lever"] == "configured" and not _is_ship(motion):
        del firmware["lever"]
    if firmware["nav_mode"] is None:
        del firmware["nav_mode"]
    references = _resolve_references(data.get("references", {}), duration_s, firmware)
    if firmware.get("coarse_method") == "fit_vel" and firmware["coarse_time_s"]:
        # under way: the GNSS velocity is the coarse alignment's measurement, the
        # navigation filter its fine alignment
        if firmware["fine_time_s"]:
            raise ScenarioError("coarse_method 'fit_vel' (under way) is followed by the navigation "
                                "filter, not a fine alignment: leave fine_time out", "firmware.fine_time")
        if firmware.get("nav_mode") == "undamped":
            raise ScenarioError("coarse_method 'fit_vel' (under way) needs the navigation filter: "
                                "nav_mode 'undamped' has none", "firmware.nav_mode")
        if "gnss" not in references:
            raise ScenarioError("coarse_method 'fit_vel' (under way) takes the ship's motion from a GNSS "
                                "velocity: give [references.gnss]", "firmware.coarse_method")
    res = {
        "schema": SCHEMA_VERSION,
        "name": name,
        "title": top["title"] if top["title"] is not None else name,
        "description": top["description"],
        "tick_s": DT,
        "duration_s": duration_s,
        "seed": top["seed"],
        "record_every_s": top["record_every"],
        "motion": motion,
        "sensors": _resolve_sensors(data.get("sensors", {})),
        "turntable": _resolve_turntable(data.get("turntable", {}), duration_s),
        "indexing": _resolve_indexing(data.get("indexing", {})),
        "firmware": firmware,
        "initial_errors": _resolve_initial_errors(data.get("initial_errors", {}), firmware),
        "outputs": _read(_need_table(data.get("outputs", {}), "outputs"), "outputs", OUTPUT_KEYS),
    }
    if references:
        res["references"] = references
    return res


# ---------------------------------------------------------------------------
# 4. Dotted key paths: [compare] and overrides
# ---------------------------------------------------------------------------
_ALTERNATIVES = {"motion.yaw": "motion.heading", "motion.heading": "motion.yaw",
                 "initial_errors.yaw": "initial_errors.heading",
                 "initial_errors.heading": "initial_errors.yaw"}
_NOT_COMPARABLE = ("name", "title", "description", "compare", "paper", "outputs")


def _set_key(data, path, value):
    """data with ``path`` ("seed", "motion.yaw") set to value (None: removed);
    the other spelling of the same quantity (yaw/heading) is removed."""
    parts = path.split(".")
    if len(parts) > 2 or not all(parts):
        raise ScenarioError("must be 'key' or 'table.key'", path)
    if len(parts) == 2:
        if parts[0] not in TABLES:
            close = difflib.get_close_matches(parts[0], TABLES, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f" (tables: {', '.join(TABLES)})"
            raise ScenarioError(f"unknown table {parts[0]!r}{hint}", path)
        table = data.setdefault(parts[0], {})
        if not isinstance(table, dict):
            raise ScenarioError("is not a table", parts[0])
    else:
        table = data
    if path in _ALTERNATIVES:
        table.pop(_ALTERNATIVES[path].split(".")[1], None)
    if value is None:
        table.pop(parts[-1], None)
    else:
        table[parts[-1]] = value


def _check_key_path(path, where):
    """``path`` ("seed", "indexing.scheme") names a key of the schema."""
    parts = path.split(".")
    if len(parts) == 1:
        allowed, name = TOP_KEYS, parts[0]
    elif len(parts) == 2 and parts[0] in TABLES:
        allowed, name = dict(TABLES[parts[0]]), parts[1]
        if parts[0] == "motion":
            for kind_keys in MOTION_KINDS.values():
                allowed.update(kind_keys)
    elif len(parts) == 2:
        close = _suggest(parts[0], TABLES)
        hint = f"; did you mean {close!r}?" if close else f" (tables: {', '.join(TABLES)})"
        raise ScenarioError(f"{path!r}: unknown table {parts[0]!r}{hint}", where)
    else:
        raise ScenarioError(f"{path!r} must be 'key' or 'table.key'", where)
    if name not in allowed:
        close = _suggest(name, allowed)
        hint = f"; did you mean {_join(parts[0] if len(parts) == 2 else '', close)!r}?" if close else ""
        raise ScenarioError(f"{path!r} is not a key{hint}", where)


