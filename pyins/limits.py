"""The firmware's configuration limits in a user's words.

The core refuses a configuration with a status code (``pyins_config_check``:
``PYINS_E_CONFIG_ALIGN_LONG`` and the like). A user who typed ``--coarse
300`` needs instead the limit, the value it was held against and the way
inside it. `explain` gives that sentence for the configuration the core
refused, naming each field the way the user wrote it: ``names`` maps a
configuration field (``coarse_ticks``) to a CLI option (``--coarse``) or a
scenario key (``firmware.coarse_time``).

The numbers come from the configuration contract
(`pyins.reference.config`, the mirror of ``csrc/src/config.cpp``): the
limits are not written a second time here.
"""
import math

from pyins import contract
from pyins import engine as engines
from pyins.reference import abi, coarse_align
from pyins.reference import config as fw_config
from pyins.units import DEG_TO_RAD

__all__ = ["check", "explain", "resolved"]


def resolved(cfg):
    """The configuration dict ``cfg`` (firmware field names, SI) completed
    with the defaults and resolved as the core resolves it."""
    full = fw_config.config_default()
    full.update(cfg)
    return fw_config.config_resolved(full)


def _s(ticks, hz):
    return f"{ticks / hz:g} s"


def lever_at_fault(cfg):
    """(field, what is wrong) of the first lever arm of ``cfg`` the core
    refuses (PYINS_E_CONFIG_LEVER), or None."""
    r = resolved(cfg)
    for field in ("lever_b_m", "lever_p_m", "dvl_lever_b_m", "gnss_lever_b_m"):
        arm = [float(x) for x in r[field]]
        if not all(math.isfinite(x) for x in arm):
            return field, "a lever arm must be finite"
        length = math.sqrt(sum(x * x for x in arm))
        if length > fw_config.MAX_LEVER_M:
            return field, f"{length:.4g} m long; a lever arm is at most {fw_config.MAX_LEVER_M:g} m long"
    return None


def explain(status, cfg, names=None):
    """A sentence saying why the core refused ``cfg`` with ``status`` and how
    to get inside the limit; ``names`` maps field names to the user's."""
    names = names or {}

    def n(field):
        return names.get(field, field)

    r = resolved(cfg)
    hz = r["tick_hz"] if r["tick_hz"] > 0 else fw_config.DEFAULT_TICK_HZ
    every, first = r["coarse_output_every_ticks"], r["coarse_first_output_ticks"]
    triad = r["coarse_method"] != abi.PYINS_COARSE_FIT     # TRIAD or eq. 8: the same history
    if status == abi.PYINS_E_CONFIG_RATE:
        return (f"{n('tick_hz')}: {cfg.get('tick_hz')} Hz is outside the rates the firmware steps at "
                f"(1 to {fw_config.MAX_TICK_HZ} Hz)")
    if status == abi.PYINS_E_CONFIG_LAT:
        return (f"{n('lat_rad')}: {math.degrees(r['lat_rad']):g} deg is outside "
                f"+-{fw_config.MAX_LAT_RAD / DEG_TO_RAD:g} deg (the East-North-Up frame is singular at "
                "the poles)")
    if status == abi.PYINS_E_CONFIG_LON:
        return f"{n('lon_rad')}: {math.degrees(r['lon_rad']):g} deg is outside +-720 deg"
    if status == abi.PYINS_E_CONFIG_HEIGHT:
        return f"{n('height_m')}: {r['height_m']:g} m is outside -10 km to 100 km"
    if status == abi.PYINS_E_CONFIG_VEL:
        return f"{n('vel_n_mps')}: each component must be finite and within +-10 km/s"
    if status == abi.PYINS_E_CONFIG_ATT:
        m = [float(x) for x in r["dvl_align_rad"]]
        if not (all(math.isfinite(x) for x in m) and math.sqrt(sum(x * x for x in m)) <= math.pi):
            return f"{n('dvl_align_rad')}: the DVL's mounting rotation must be finite and at most 180 deg long"
        return f"{n('euler_b_rad')}: the initial attitude and table angle must be finite"
    if status == abi.PYINS_E_CONFIG_ALIGN_TICKS:
        if r["coarse_ticks"] > 0 and first > r["coarse_ticks"]:
            earlier = (f" (or set {names['coarse_first_output_ticks']} earlier)"
                       if "coarse_first_output_ticks" in names else "")
            return (f"{n('coarse_ticks')}: a coarse alignment of {_s(r['coarse_ticks'], hz)} ends before "
                    f"its first solution at {_s(first, hz)}: align for at least {_s(first, hz)}"
                    + earlier)
        return f"{n('coarse_ticks')}: alignment times must not be negative"
    if status == abi.PYINS_E_CONFIG_ALIGN_RATIO:
        return f"{n('coarse_ratio')}: {r['coarse_ratio']:g} must lie strictly between 0 and 1"
    if status == abi.PYINS_E_CONFIG_ALIGN_EARLY:
        if not triad:
            need = coarse_align.FIT_MIN_INTERVALS * every
            return (f"{names.get('coarse_output_every_ticks', 'coarse_output_every_ticks')}: FIT needs {coarse_align.FIT_MIN_INTERVALS} output "
                    f"intervals before its first solution: with a {_s(every, hz)} interval the first "
                    f"solution comes at {_s(need, hz)} or later, not at {_s(first, hz)}")
        return (f"{n('coarse_first_output_ticks')}: the first coarse solution at {_s(first, hz)} times the "
                f"ratio {r['coarse_ratio']:g} leaves less than one output interval ({_s(every, hz)})")
    if status == abi.PYINS_E_CONFIG_ALIGN_LONG:
        longest = (coarse_align.HIST_LEN - 1) * every
        return (f"{n('coarse_ticks')}: a TRIAD (or eq. 8) coarse alignment keeps {coarse_align.HIST_LEN - 1} output "
                f"intervals, so with a {_s(every, hz)} interval it lasts at most {_s(longest, hz)}, not "
                f"{_s(r['coarse_ticks'], hz)}: a {_s(2 * every, hz)} interval "
                f"({n('coarse_output_every_ticks')}) allows {_s(2 * longest, hz)}, and "
                f"{n('coarse_method')} fit has no length limit")
    if status == abi.PYINS_E_CONFIG_FINE:
        return (f"{n('fine_states')}: the fine filter has 5, 8 or 12 states, not {r['fine_states']} "
                "(or the fine correction mode or measurement interval is not one the firmware knows)")
    if status == abi.PYINS_E_CONFIG_NOISE:
        return ("the fine filter's noise densities and initial sigmas "
                f"({n('fine_gyro_arw')}, {n('fine_accel_vrw')}, {n('fine_sigma0_att_rad')}, ...) must "
                "be positive and finite")
    if status == abi.PYINS_E_CONFIG_LEVER:
        fault = lever_at_fault(cfg)
        if fault is not None:
            return f"{n(fault[0])}: {fault[1]}"
    if status == abi.PYINS_E_CONFIG_COARSE_METHOD:
        return f"{n('coarse_method')}: triad, fit or eq8"
    return f"the firmware refuses the configuration: {contract.status_str(status)}"


def check(cfg, names=None):
    """None when the core accepts ``cfg``, else (status, sentence)."""
    status = engines.config_check(cfg)
    if status == 0:
        return None
    return status, explain(status, cfg, names)
