"""Building what runs from a resolved scenario: the ship's motion, the
sensor errors, the turntable, the firmware's configuration, and the initial
state handed to the firmware (the truth at t = 0, plus the file's initial
errors), each built once here; `RunSpec` holds them for one run
(`pyins.run_scenario.run` runs it).

The firmware's own check of a configuration (``pyins_config_check``) runs
at load time (`_firmware_check`), so a refused value names its key.
"""
from dataclasses import dataclass

import numpy as np

from pyins import contract, limits, sim
from pyins import engine as engines
from pyins.reference import abi, attitude, earth
from pyins.scenario.schema import (COARSE_METHODS, FINE_CORRECTIONS, FINE_NOISES, INDEX_SUMS, NAV_MODES, VERTICAL_MODES,
                                   _LINEAR_AXES, _STEP_MOVES, _TABLE_FAULTS)
from pyins.sim import references, turntable, voyage
from pyins.units import DT, TICK_HZ, ScenarioError

# ---------------------------------------------------------------------------
# 1. The ship's motion
# ---------------------------------------------------------------------------
_SHIP_RESOLVED = ("heave", "surge", "sway", "spectrum", "lever_b_m", "lever_p_m")


def _is_ship(m):
    """True when a resolved [motion] is a pyins.sim.ShipAtSea: any ship key,
    or a ship at anchor."""
    return m.get("kind") == "at_anchor" or any(k in m for k in _SHIP_RESOLVED)


def _build_motion(m):
    """A pyins.sim motion object from a resolved [motion] dict: the base
    profile, wrapped in a ShipAtSea when any ship key is given."""
    base = _build_base_motion(m)
    if not _is_ship(m):
        return base
    linear = None
    if "spectrum" in m:
        linear = _spectrum_motion(m["spectrum"])
    elif any(a in m for a in _LINEAR_AXES):
        linear = sim.LinearMotion(**{a: [(c["amplitude_m"], c["period_s"], c["phase_rad"])
                                         for c in m.get(a, [])] for a in _LINEAR_AXES})
    if m["kind"] == "at_anchor":      # the arc about the anchor, with the waves' heave, surge and sway on it
        surge, sway = sim.anchor_linear(m["radius_m"], m["swing_period_s"], m["swing_angle_rad"],
                                        m["swing_phase_rad"])
        waves = linear if linear is not None else sim.LinearMotion()
        linear = sim.LinearMotion(heave=waves.heave, surge=tuple(surge) + tuple(waves.surge),
                                  sway=tuple(sway) + tuple(waves.sway))
    return sim.ShipAtSea(base, linear, lever_b=m.get("lever_b_m", (0.0, 0.0, 0.0)),
                         lever_p=m.get("lever_p_m", (0.0, 0.0, 0.0)))


def _build_base_motion(m):
    """The profile of a resolved [motion] dict without its ship keys."""
    kind = m["kind"]
    lat, lon, h = m["lat_rad"], m["lon_rad"], m["height_m"]
    if kind == "static":
        return sim.Static(lat, lon, h, m["pitch_rad"], m["roll_rad"], m["yaw_rad"])
    if kind == "swing":
        return sim.Swing(lat, lon, h, m["pitch_rad"], m["roll_rad"], m["yaw_rad"],
                         m["amplitude_rad"], m["frequency_hz"], m["phase_rad"])
    if kind == "sea_state":
        return sim.sea_state(m["sea_state"], lat, lon, h, m["yaw_rad"], m["pitch_rad"], m["roll_rad"],
                             m["phase_rad"])
    if kind == "at_anchor":
        return sim.anchor_swing(m["sea_state"], lat, lon, h, m["yaw_rad"], m["swing_period_s"],
                                m["swing_angle_rad"], m["swing_phase_rad"], m["pitch_rad"], m["roll_rad"])
    if kind == "heading_swing":
        return sim.HeadingSwing(lat, lon, h, m["pitch_rad"], m["roll_rad"], m["yaw_rad"],
                                m["rate_amplitude_rad_s"], m["period_s"])
    if kind == "voyage":
        yaw0, speed0, legs = voyage.voyage_segments(m["duration_s"] / 3600.0, seed=m["route_seed"], dt=DT)
        if m["yaw_rad"] is not None:
            yaw0 = m["yaw_rad"]
        if m.get("speed_mps") is not None:
            speed0 = m["speed_mps"]
        if m.get("segments") is not None:         # a chosen track instead of the route's
            legs = [sim.Segment(s["kind"], round(s["duration_s"] * TICK_HZ), s["value"])
                    for s in m["segments"]]
        current = None
        if any(m["current_mps"]) or m["current_tide_mps"]:
            current = references.Current(mean_enu=m["current_mps"], amplitude_mps=m["current_tide_mps"],
                                         seed=m["route_seed"])
        return sim.Voyage(lat, lon, h, yaw0, legs, speed0=speed0, dt=DT,
                          sea=None if m["sea"] == "none" else m["sea"], pitch0=m["pitch_rad"],
                          roll0=m["roll_rad"], current=current)
    if m["segments"] == "default":
        segments = sim.default_segments(DT)
    else:
        segments = [sim.Segment(s["kind"], round(s["duration_s"] * TICK_HZ), s["value"])
                    for s in m["segments"]]
    try:
        return sim.Manoeuvre(lat, lon, h, m["yaw_rad"], segments, dt=DT, speed0=m["speed_mps"],
                             pitch=m["pitch_rad"], roll=m["roll_rad"])
    except ValueError as exc:
        raise ScenarioError(str(exc), "motion.segments") from None


def _spectrum_motion(sp):
    return sim.sea_spectrum_motion(sp["hs_m"], sp["tp_s"], spectrum=sp["kind"],
                                   gamma=sp["gamma"] if sp["gamma"] is not None else 1.0,
                                   seed=sp["seed"], n_components=sp["components"])


# ---------------------------------------------------------------------------
# 2. The initial state: the truth at t = 0, and the file's errors on it
# ---------------------------------------------------------------------------
def initial_truth(motion):
    """(lat, lon, height, vel_n, euler) of ``motion`` at t = 0.

    A ShipAtSea: its reference point's state, which the firmware's
    configuration and records mean when a lever arm is configured; every
    other profile: its own state. A Manoeuvre in closed form (its ``state``
    would integrate the whole track first; the two agree bit for bit).
    """
    if isinstance(motion, sim.Manoeuvre) and motion.current is None:
        speed, _, yaw, _ = motion.kinematics(0.0)
        speed, yaw = float(speed), float(yaw)
        return (motion.lat0, motion.lon0, motion.height,
                np.array([-speed * np.sin(yaw), speed * np.cos(yaw), 0.0]),
                np.array([motion.pitch, motion.roll, yaw]))
    state = motion.reference_state if hasattr(motion, "reference_state") else motion.state
    st = state(np.array([0.0]))
    return float(st.lat[0]), float(st.lon[0]), float(st.height[0]), st.vel_n[0], st.euler[0]


def initial_config(motion, table=None, **overrides):
    """Firmware configuration holding the true state of ``motion`` at t = 0
    (`initial_truth`) and the table angle of the profile ``table`` (None: 0).

    A ShipAtSea's lever arms ``lever_b_m``/``lever_p_m`` go with it unless
    overridden; ``overrides`` replace any field.
    """
    lat, lon, h, vel, euler = initial_truth(motion)
    if hasattr(motion, "reference_state"):
        overrides = {"lever_b_m": np.asarray(motion.lever_b, dtype=float),
                     "lever_p_m": np.asarray(motion.lever_p, dtype=float), **overrides}
    alpha0 = 0.0 if table is None else float(table.state(np.array([0.0]))[0][0])
    cfg = dict(lat_rad=lat, lon_rad=lon, height_m=h, vel_n_mps=vel, euler_b_rad=euler,
               table_angle_rad=alpha0)
    cfg.update(overrides)
    return cfg


def initial_errors(motion, *, phi=None, pitch=None, roll=None, yaw=None, velocity=None, north=None,
                   east=None, height=None, zero_attitude=False):
    """The configuration fields of an initial state with errors: the truth of
    ``motion`` at t = 0 (`initial_truth`) plus the errors given (None: that
    field is left to the truth and not returned).

    ``phi`` [rad, E N U]: C(firmware) = (I - phi x) C(true), or Euler angle
    errors ``pitch``/``roll``/``yaw`` [rad]; ``zero_attitude``: all Euler
    angles zero instead; ``velocity`` [m/s, E N U]; ``north``/``east``/
    ``height`` [m], the position errors over the radii of curvature at the
    ellipsoid.
    """
    lat, lon, h, vel, euler = initial_truth(motion)
    cfg = {}
    if zero_attitude:
        cfg["euler_b_rad"] = [0.0, 0.0, 0.0]
    elif phi is not None:
        cfg["euler_b_rad"] = attitude.mat_to_euler(attitude.rotvec_to_mat(-np.array(phi))
                                                   @ attitude.euler_to_mat(euler))
    elif any(v is not None for v in (pitch, roll, yaw)):
        cfg["euler_b_rad"] = euler + np.array([pitch or 0.0, roll or 0.0, yaw or 0.0])
    if velocity is not None:
        cfg["vel_n_mps"] = vel + np.array(velocity)
    rm, rn = earth.principal_radii(np.sin(lat))
    if north is not None:
        cfg["lat_rad"] = lat + north / rm
    if east is not None:
        cfg["lon_rad"] = lon + east / (rn * np.cos(lat))
    if height is not None:
        cfg["height_m"] = h + height
    return cfg


# ---------------------------------------------------------------------------
# 3. The firmware configuration, sensor errors and turntable of a variant
# ---------------------------------------------------------------------------
def _ticks(seconds):
    return int(round(seconds * TICK_HZ))


def _firmware_config(res, motion):
    """The overrides for ``fil.run_fil(config=...)``: only what the scenario
    sets (keys it leaves unset keep the firmware's defaults, and the initial
    state is the truth, filled in by `initial_config`); ``motion`` is the
    variant's (`_build_motion`)."""
    fw, ix, ie = res["firmware"], res["indexing"], res["initial_errors"]
    cfg = {"index_scheme": ix["scheme_number"]}
    if fw["vertical_mode"] is not None:
        cfg["vertical_mode"] = VERTICAL_MODES[fw["vertical_mode"]]
    for name, c_name in (("coarse_time_s", "coarse_ticks"),
                         ("coarse_first_output_s", "coarse_first_output_ticks"),
                         ("coarse_output_every_s", "coarse_output_every_ticks"),
                         ("fine_time_s", "fine_ticks"), ("fine_meas_every_s", "fine_meas_every_ticks")):
        if fw[name] is not None:
            cfg[c_name] = _ticks(fw[name])
    for name, c_name in (("coarse_ratio", "coarse_ratio"), ("fine_states", "fine_states"),
                         ("fine_gyro_arw_rad_sqrt_s", "fine_gyro_arw"),
                         ("fine_accel_vrw_mps_sqrt_s", "fine_accel_vrw"),
                         ("fine_sigma0_att_rad", "fine_sigma0_att_rad"),
                         ("fine_sigma0_gyro_rad_s", "fine_sigma0_gyro"),
                         ("fine_sigma0_accel_mps2", "fine_sigma0_accel"),
                         ("fine_site_accel_mps_sqrt_s", "fine_site_accel"),
                         ("nav_gyro_bias_rw_rad_s_sqrt_s", "nav_gyro_bias_rw"),
                         ("nav_table_scale_sigma", "nav_table_scale_sigma"),
                         ("nav_table_mis_sigma_rad", "nav_table_mis_sigma"),
                         ("nav_level_scale_sigma", "nav_level_scale_sigma"),
                         ("nav_level_mis_sigma_rad", "nav_level_mis_sigma")):
        if fw[name] is not None:
            cfg[c_name] = fw[name]
    if fw["fine_correction"] is not None:
        cfg["fine_correction"] = FINE_CORRECTIONS[fw["fine_correction"]]
    if fw.get("fine_noise") is not None:
        cfg["fine_noise"] = FINE_NOISES[fw["fine_noise"]]
    if fw.get("coarse_method") is not None:
        cfg["coarse_method"] = COARSE_METHODS[fw["coarse_method"]]
    if fw.get("nav_mode") is not None:
        cfg["nav_mode"] = NAV_MODES[fw["nav_mode"]]
    if fw.get("lever") == "unknown":
        # what an unknown lever arm costs: the firmware navigates the reference point as if
        # the accelerometers were there (initial_config would give it the motion's)
        cfg["lever_b_m"] = [0.0, 0.0, 0.0]
        cfg["lever_p_m"] = [0.0, 0.0, 0.0]
    gnss = (res.get("references") or {}).get("gnss")
    if gnss is not None and (gnss["lever_m"] is not None and any(x != 0.0 for x in gnss["lever_m"])
                             or gnss["lever_told_m"] is not None):
        # the antenna's lever arm as the firmware is told it (only when there is one: the
        # configuration of a scenario without one is what it always was)
        told = gnss["lever_told_m"]
        cfg["gnss_lever_b_m"] = list(gnss["lever_m"] if told is None else told)
    dvl = (res.get("references") or {}).get("dvl")
    if dvl is not None:
        # the DVL's mounting as the firmware is told it (only with a DVL: the
        # configuration of a scenario without one is what it always was)
        told = dvl["misalignment_told_rad"]
        cfg["dvl_align_rad"] = list(dvl["misalignment_rad"] if told is None else told)
        cfg["dvl_lever_b_m"] = list(dvl["lever_m"])
    for name, c_name in (("stop_s", "index_stop_ticks"), ("timeout_s", "index_timeout_ticks")):
        if ix[name] is not None:
            cfg[c_name] = _ticks(ix[name])
    for name, c_name in (("rate_rad_s", "index_rate_rad_s"), ("acceleration_rad_s2", "index_accel_rad_s2"),
                         ("delta", "index_delta"), ("max_flex_rad", "index_max_flex_rad"),
                         ("tolerance_rad", "index_tolerance_rad"), ("jump_rad", "index_jump_rad")):
        if ix[name] is not None:
            cfg[c_name] = ix[name]
    if ix["sums"] != "stops":
        cfg["index_sums"] = INDEX_SUMS[ix["sums"]]
    if ix["steps"] is not None:
        cfg["index_n_steps"] = len(ix["steps"])
        cfg["index_steps"] = [(_ticks(s["stop_s"]), _STEP_MOVES[s["move"]], s["angle_rad"])
                              for s in ix["steps"]]
    if res["turntable"]["initial_angle_rad"] != 0.0:
        cfg["table_angle_rad"] = res["turntable"]["initial_angle_rad"]

    # the initial state: the truth plus the initial errors
    cfg.update(initial_errors(motion, phi=ie["phi_rad"], pitch=ie["pitch_rad"], roll=ie["roll_rad"],
                              yaw=ie["yaw_rad"], velocity=ie["velocity_mps"], north=ie["north_m"],
                              east=ie["east_m"], height=ie["height_m"],
                              zero_attitude=fw["initial_attitude"] == "zero"))
    return cfg


def _sensor_errors(s):
    return sim.SensorErrors(
        gyro_bias=np.array(s["gyro_bias_rad_s"]), gyro_scale=np.array(s["gyro_scale"]),
        gyro_misalignment=np.array(s["gyro_misalignment_rad"]), gyro_arw=s["gyro_arw_rad_sqrt_s"],
        gyro_quantum=s["gyro_quantum_rad"], accel_bias=np.array(s["accel_bias_mps2"]),
        accel_scale=np.array(s["accel_scale"]), accel_misalignment=np.array(s["accel_misalignment_rad"]),
        accel_vrw=s["accel_vrw_mps_sqrt_s"], accel_quantum=s["accel_quantum_mps"])


def _table_config(t):
    return turntable.TableConfig(rate_max_rad_s=t["rate_max_rad_s"], accel_max_rad_s2=t["accel_max_rad_s2"],
                                 encoder_lsb_rad=t["encoder_lsb_rad"], jump_rad=t["jump_rad"],
                                 fault_tick=_ticks(t["fault_time_s"]), fault=_TABLE_FAULTS[t["fault"]])


#: pyins_status name -> the scenario key it most likely concerns.
_STATUS_KEYS = {
    "PYINS_E_CONFIG_LAT": "motion.lat", "PYINS_E_CONFIG_LON": "motion.lon",
    "PYINS_E_CONFIG_HEIGHT": "motion.height", "PYINS_E_CONFIG_VEL": "initial_errors.velocity",
    "PYINS_E_CONFIG_ATT": "motion", "PYINS_E_CONFIG_MODE": "firmware.vertical_mode",
    "PYINS_E_CONFIG_ALIGN_RATIO": "firmware.coarse_ratio",
    "PYINS_E_CONFIG_ALIGN_EARLY": "firmware.coarse_first_output",
    "PYINS_E_CONFIG_ALIGN_LONG": "firmware.coarse_time",
    "PYINS_E_CONFIG_ALIGN_TICKS": "firmware.coarse_time", "PYINS_E_CONFIG_FINE": "firmware.fine_states",
    "PYINS_E_CONFIG_NOISE": "firmware", "PYINS_E_CONFIG_INDEX_SCHEME": "indexing.scheme",
    "PYINS_E_CONFIG_INDEX_EMPTY": "indexing.steps", "PYINS_E_CONFIG_INDEX_RATE": "indexing.rate",
    "PYINS_E_CONFIG_INDEX_DELTA": "indexing.delta", "PYINS_E_CONFIG_INDEX_STEP": "indexing",
    "PYINS_E_CONFIG_INDEX_SUMS": "indexing.sums", "PYINS_E_CONFIG_LEVER": "motion.lever_b",
    "PYINS_E_CONFIG_COARSE_METHOD": "firmware.coarse_method",
}


#: the firmware fields as a scenario file names them (`pyins.limits`)
_FIELD_KEYS = {"lat_rad": "motion.lat", "lon_rad": "motion.lon", "height_m": "motion.height",
               "lever_b_m": "motion.lever_b", "lever_p_m": "motion.lever_p",
               "dvl_lever_b_m": "references.dvl.lever", "gnss_lever_b_m": "references.gnss.lever (or lever_told)",
               "vel_n_mps": "initial_errors.velocity", "euler_b_rad": "motion",
               "coarse_ticks": "firmware.coarse_time", "coarse_ratio": "firmware.coarse_ratio",
               "coarse_first_output_ticks": "firmware.coarse_first_output",
               "coarse_output_every_ticks": "firmware.coarse_output_every",
               "coarse_method": "firmware.coarse_method", "fine_states": "firmware.fine_states",
               "fine_gyro_arw": "firmware.fine_gyro_arw", "fine_accel_vrw": "firmware.fine_accel_vrw",
               "fine_sigma0_att_rad": "firmware.fine_sigma0_att",
               "fine_site_accel": "firmware.fine_site_accel",
               "nav_gyro_bias_rw": "firmware.nav_gyro_bias_rw",
               "nav_table_scale_sigma": "firmware.nav_table_scale_sigma",
               "nav_table_mis_sigma": "firmware.nav_table_mis_sigma",
               "nav_level_scale_sigma": "firmware.nav_level_scale_sigma",
               "nav_level_mis_sigma": "firmware.nav_level_mis_sigma"}


def _firmware_check(motion, cfg):
    """The firmware's own check (pyins_config_check) of the configuration a
    run of ``motion`` with the overrides ``cfg`` hands it."""
    full = initial_config(motion, None, **cfg)
    status = engines.config_check(full)
    if status != 0:
        name = contract.status_str(status).split(":")[0]
        said = f"the firmware refuses the configuration: {contract.status_str(status)}"
        why = limits.explain(status, full, _FIELD_KEYS)
        key = _STATUS_KEYS.get(name, "firmware")
        fault = limits.lever_at_fault(full) if status == abi.PYINS_E_CONFIG_LEVER else None
        if fault is not None:
            key = _FIELD_KEYS[fault[0]]       # the arm at fault, not the first of them
        raise ScenarioError(said if why == said else f"{said} ({why})", key)


# ---------------------------------------------------------------------------
# 4. One run
# ---------------------------------------------------------------------------
@dataclass
class RunSpec:
    """One run of a scenario: everything ``pyins.fil.run_fil`` needs
    (`pyins.run_scenario.run` runs it)."""
    label: str                    #: the [compare] label (the scenario name without [compare])
    index: int                    #: position among the scenario's runs
    scenario: str                 #: the scenario's name
    motion: object                #: a pyins.sim motion profile (fresh object per RunSpec)
    errors: object                #: pyins.sim.SensorErrors
    config: dict                  #: firmware configuration overrides (fil.run_fil config=)
    table: object                 #: pyins.sim.turntable.TableConfig
    duration_ticks: int
    seed: int
    every: int                    #: record interval [ticks]
    dt: float = DT
    outputs: dict = None          #: the resolved [outputs] (plots, csv, records)
    refs: object = None           #: external references (contract.REF_DTYPE) or None
    avail_tick: object = None     #: the tick each reaches the firmware (a receiver's latency), or None


def _references(res, motion):
    """(refs, avail_tick) of the resolved [references]: the simulated GNSS
    receiver's fixes, the speed log's and the DVL's readings and the
    zero-velocity declarations, merged by tick (`pyins.sim.references`);
    (None, None) without any."""
    rt = res.get("references")
    if not rt:
        return None, None
    duration = res["duration_s"]
    parts = []
    g = rt.get("gnss")
    if g is not None:
        outages = [tuple(w) for w in g["outages"]]
        if g["outage_every_s"]:
            t = g["outage_from_s"]
            while t < duration:
                outages.append((t, t + g["outage_length_s"]))
                t += g["outage_every_s"]
        parts.append(references.gnss(motion, duration, dt=DT, rate_hz=g["rate_hz"], pos_noise_m=g["pos_noise_m"],
                                     vel_noise_mps=g["vel_noise_mps"], bias_sigma_m=g["bias_sigma_m"],
                                     bias_tau_s=g["bias_tau_s"], latency_s=g["latency_s"], outages=outages,
                                     outlier_rate=g["outlier_rate"], frozen=[tuple(w) for w in g["frozen"]],
                                     seed=g["seed"], velocity=g["velocity"], position=g["position"], lever_b=tuple(g["lever_m"])))
    lg = rt.get("speed_log")
    if lg is not None:
        # the water the ship moves in: a voyage's current (another motion: still water)
        log = references.speed_log(motion, duration, getattr(motion, "current", None), rate_hz=lg["rate_hz"],
                                   scale_factor=lg["scale_factor"], bias_mps=lg["bias_mps"],
                                   noise_mps=lg["noise_mps"], seed=lg["seed"], dt=DT)
        log.refs["sigma"][:, 0] = lg["sigma_mps"]      # what the firmware is told
        parts.append(log)
    dv = rt.get("dvl")
    if dv is not None:
        # bottom track: the velocity over ground (no current), in the DVL's frame
        d = references.dvl(motion, duration, None, misalignment_rad=dv["misalignment_rad"],
                           scale_factor=dv["scale_factor"], noise_mps=dv["noise_mps"], rate_hz=dv["rate_hz"],
                           lever_b=dv["lever_m"], seed=dv["seed"], dt=DT)
        d.refs["sigma"] = dv["sigma_mps"]              # what the firmware is told
        parts.append(d)
    z = rt.get("zero_velocity")
    if z is not None:
        fw = res["firmware"]
        start = z["start_s"] if z["start_s"] is not None else (fw["coarse_time_s"] or 0.0) + (fw["fine_time_s"] or 0.0)
        parts.append(references.zero_velocity(max(duration - start, 0.0), rate_hz=z["rate_hz"],
                                              sigma_mps=z["sigma_mps"], t0_s=start, dt=DT))
    merged = references.merge(*parts) if len(parts) > 1 else parts[0]
    refs = np.ascontiguousarray(merged.refs, dtype=contract.REF_DTYPE)
    # a ship's computer receives them in order: one reaches it no earlier than
    # those before it (a receiver's latency beside undelayed declarations)
    avail = np.maximum.accumulate(np.asarray(merged.avail_tick, dtype=np.int64))
    return refs, avail


def _runspec(res, label, index):
    """The RunSpec of one resolved variant."""
    motion = _build_motion(res["motion"])
    refs, avail = _references(res, motion)
    return RunSpec(label=label, index=index, scenario=res["name"], motion=motion,
                   errors=_sensor_errors(res["sensors"]), config=_firmware_config(res, motion),
                   table=_table_config(res["turntable"]), duration_ticks=_ticks(res["duration_s"]),
                   seed=res["seed"], every=_ticks(res["record_every_s"]), dt=DT,
                   outputs=dict(res["outputs"]), refs=refs, avail_tick=avail)


