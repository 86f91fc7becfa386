"""The golden regression cases: short input streams through every firmware
mode and indexing scheme, whose output records are stored bit for bit in
tests/regression/data/ (tools/regenerate_golden.py writes them, on purpose
only; test_golden.py holds the firmware to them).

Each case is a configuration and an input stream. The inputs are stored
with the expected records, so a change in the simulator cannot pass for a
change in the firmware. Durations are short (20-30 s at 100 Hz) with short
alignment grids and stops, so every mode and every branch of a scheme runs.
"""
import numpy as np

from pyins import native, scenario, sim
from pyins import units

DEG = units.DEG_TO_RAD
LAT, LON, HEIGHT = 34.246 * DEG, 108.910 * DEG, 380.0
N_TICKS = 2500
#: Stored records: every this many ticks, plus a SHA-256 over every tick's record.
EVERY = 25

_SHORT_COARSE = dict(coarse_ticks=600, coarse_first_output_ticks=400, coarse_output_every_ticks=50)
_SHORT_FINE = dict(fine_ticks=600)


def _swing(yaw=0.7):
    return sim.sea_state("general", LAT, LON, HEIGHT, yaw0=yaw)


def _moored(yaw=0.7):
    return sim.moored("general", LAT, LON, HEIGHT, yaw)


def _heading_swing():
    return sim.HeadingSwing(LAT, LON, HEIGHT, 1 * DEG, -2 * DEG, -15 * DEG, 6 * DEG, 60.0)


def _scheme(n, **extra):
    return dict(index_scheme=n, index_stop_ticks=300, **extra)


#: name -> (motion factory, configuration overrides, sensor preset or None, seq faults)
CASES = {
    "nav_static": (lambda: sim.Static(LAT, LON, HEIGHT, 0.01, -0.02, 1.0), {}, "seed001", False),
    "nav_swing_free": (_swing, dict(vertical_mode=1), "seed002", False),
    "coarse_triad_fine5": (_swing, dict(**_SHORT_COARSE, **_SHORT_FINE, fine_states=5), "seed000", False),
    "coarse_triad_fine8_open": (_swing, dict(**_SHORT_COARSE, **_SHORT_FINE, fine_states=8,
                                             fine_correction=1, coarse_ratio=0.25), "seed000", False),
    "coarse_eq8_fine5": (_swing, dict(**_SHORT_COARSE, **_SHORT_FINE, fine_states=5, coarse_method=2),
                         "seed000", False),
    "moored_fit_fine12": (_moored, dict(**_SHORT_COARSE, **_SHORT_FINE, coarse_method=1,
                                        fine_states=12, fine_meas_every_ticks=20,
                                        integrity_nis_window=5), "seed000", False),
    "moored_fit_fine5_inconsistent": (_moored, dict(**_SHORT_COARSE, **_SHORT_FINE, coarse_method=1,
                                                    fine_states=5, integrity_nis_window=20),
                                      "seed000", False),
    "moored_lever_nav": (_moored, {}, None, False),
    "index_single_fwd_rev": (_swing, _scheme(1), "seed003", False),
    "index_two_position": (_heading_swing, _scheme(2), "seed002", False),
    "index_four_position": (_heading_swing, _scheme(3), "seed002", False),
    "index_flexible": (_heading_swing, _scheme(4, index_delta=0.05), "seed002", False),
    "index_flexible_derived_sums": (_heading_swing, _scheme(6, index_sums=1, index_delta=0.05),
                                    "seed002", False),
    "index_custom": (_heading_swing, dict(index_scheme=5, index_n_steps=2, index_rate_rad_s=0.2,
                                          index_accel_rad_s2=1.0, index_delta=0.05,
                                          index_steps=[(200, 1, 1.5), (150, 2, -1.0)]),
                     "seed002", False),
    "faults_seq_nan_gap": (_swing, dict(**_SHORT_COARSE, fine_ticks=300, seq_mode=1), "seed000", True),
    "index_heading_isolation": (_heading_swing, _scheme(7), "seed002", False),
}
#: Cases whose stored increments are the ship's (frame b) and which the
#: harness turns with the table it commands (`_turned`): heading isolation
#: counter-rotates against the ship's yaw as the firmware measures it, so a
#: table that did not turn the gyros would feed its own command back.
TURNS = {"index_heading_isolation"}


def inputs(name):
    """The input stream of a case: (config dict, dtheta (N, 3), dv (N, 3), table (N,), seq (N,))."""
    make, overrides, preset, faults = CASES[name]
    m = make()
    dtheta, dv, table = sim.exact_increments(m, N_TICKS)
    if preset is not None:
        model = sim.SensorModel(sim.preset(preset), seed=sum(map(ord, name)))
        dtheta, dv = model.apply(dtheta, dv)
    cfg = scenario.initial_config(m, None, **overrides)
    seq = np.arange(1, N_TICKS + 1, dtype=np.int64)
    if faults:
        seq[700:] += 1            # one tick missing in fine alignment (restart)
        seq[1500:] += 2           # two missing in navigation (bridged)
        dv[1800, 0] = np.nan      # rejected
    return cfg, dtheta, dv, table, seq


def _turned(dtheta_b, dv_b, alpha0, alpha1):
    """The ship's increments of a tick in the frame p of a table that turned
    from alpha0 to alpha1 during it, to first order: Rz(mid)^T v, plus the
    turn about z (the plant's omega_ip^p = Rz(alpha)^T omega_ib^b + alpha_dot
    z). Sine and cosine are the core's portable ones (the test hooks), so
    the bits are the same on every machine."""
    lib = native.lib
    mid = 0.5 * (alpha0 + alpha1)
    c, s = lib.pyins_t_cos(mid), lib.pyins_t_sin(mid)

    def rot(v):
        return (c * v[0] + s * v[1], -s * v[0] + c * v[1], v[2])
    th = rot(dtheta_b)
    return (th[0], th[1], th[2] + (alpha1 - alpha0)), rot(dv_b)


def _closed(cfg, dtheta, dv, seq, dtype, step, turn=False):
    """Every tick's record of ``dtype``, stepping one sample at a time with
    ``step(fw, sample)`` (the record it leaves, a cffi pointer); the encoder
    reads back the last commanded table angle (an ideal table, as in the
    embedded demo). The increments turn with it only when ``turn`` (the
    cases of TURNS: `_turned`); else they are given in p as they are (the
    records test bits, not physics)."""
    ffi = native.ffi
    fw = native.Firmware(cfg)
    out = np.zeros(len(dtheta), dtype=dtype)
    sample = ffi.new("pyins_sample *")
    enc = float(cfg.get("table_angle_rad", 0.0))
    alpha = enc                       # the table's unwrapped angle at the tick's start
    two_pi = 2.0 * np.pi
    for k in range(len(dtheta)):
        th, v = dtheta[k], dv[k]
        if turn:                      # the table turned to the reading, the short way
            to = alpha + float(np.remainder(enc - alpha + np.pi, two_pi) - np.pi)
            th, v = _turned(th, v, alpha, to)
            alpha = to
        for i in range(3):
            sample.dtheta_p_rad[i] = th[i]
            sample.dv_p_mps[i] = v[i]
        sample.table_angle_rad = enc
        sample.seq = int(seq[k]) & 0xFFFFFFFF
        rec = step(fw, sample)
        out[k] = np.frombuffer(ffi.buffer(ffi.addressof(rec), dtype.itemsize), dtype=dtype)[0]
        enc = float(rec.table_angle_cmd_rad) % two_pi
    return out


def run(cfg, dtheta, dv, seq, turn=False):
    """Every tick's output record (OUTPUT_DTYPE, one per sample) through
    pyins_step (_closed). A rejected sample keeps the record the call wrote."""
    rec = native.ffi.new("pyins_output *")

    def step(fw, sample):
        native.lib.pyins_step(fw.core, sample, rec)
        return rec[0]
    return _closed(cfg, dtheta, dv, seq, native.OUTPUT_DTYPE, step, turn)


def run_compact(cfg, dtheta, dv, seq, turn=False):
    """As run(), through pyins_run_nav one sample at a time (out_every 1):
    every tick's compact record (NAV_DTYPE). A sample that adds no tick (a
    dropped duplicate) or is rejected writes none: pyins_get_nav then gives
    the state, as pyins_step's record would."""
    ffi, lib = native.ffi, native.lib
    nav = ffi.new("pyins_nav[2]")
    n_done = ffi.new("size_t *")
    n_out = ffi.new("size_t *")

    def step(fw, sample):
        lib.pyins_run_nav(fw.core, sample, 1, 1, nav, 2, n_done, n_out)
        if n_out[0] == 0:
            assert lib.pyins_get_nav(fw.core, nav) == 0
        return nav[0]
    return _closed(cfg, dtheta, dv, seq, native.NAV_DTYPE, step, turn)
