"""The engine choice: the compiled firmware or its NumPy reference mirror,
behind one contract.

``engine="native"`` runs the C++ core (`pyins.native.Firmware`) and, in a
closed loop, the compiled plant (`pyins.native.Plant`); ``"reference"`` runs
the NumPy mirror of the core (`pyins.reference.Firmware`, the same
constructor, ``step``, ``run``, ``snapshot``/``restore`` and records of
``native.OUTPUT_DTYPE``) and the NumPy mirror of the plant (`MirrorPlant`,
over `pyins.sim.turntable`), three orders of magnitude slower (`pyins bench`). Everything above
(open_loop, fil, run_scenario, the CLI's ``--engine``) is the same code for both.

The reference engine needs no compiled library: `pyins.native` is imported
here once at module level, and a failure (no library built, a stale one) is
kept: asking for the native engine then raises ImportError with the loader's
message (`native_error`), while the reference engine goes on. The records,
errors and samples of both are `pyins.contract`'s.
"""
import json

import numpy as np

from pyins import contract, reference
from pyins.sim import turntable

try:
    from pyins import native
except ImportError as _exc:   # no (or a stale) libpyins_core.so: the reference engine only
    native = None
    _NATIVE_ERROR = str(_exc)
else:
    _NATIVE_ERROR = None

ENGINES = ("native", "reference")


def native_error():
    """None when the native engine is available, else why it is not (the
    ImportError's message of `pyins.native`)."""
    return _NATIVE_ERROR


def core_version():
    """The compiled core's version string (what run summaries record), or
    what stands in its place when the library is not there."""
    if native is None:
        return "none (no compiled library: the reference engine only)"
    return native.version()


def core_abi():
    """The compiled core's ABI as "major.minor", or None without the library."""
    return None if native is None else ".".join(map(str, native.abi_version()))


def check(engine):
    """``engine`` if it is one of ENGINES, else ValueError."""
    if engine not in ENGINES:
        raise ValueError(f"engine: {engine!r} is not one of {', '.join(ENGINES)}")
    return engine


def _native():
    """`pyins.native`, or ImportError saying why it could not be loaded."""
    if native is None:
        raise ImportError(f"engine 'native' is not available ({_NATIVE_ERROR}); "
                          f"engine='reference' runs without the compiled library")
    return native


def config_check(fields):
    """The firmware's check of a configuration dict (named like the C
    fields): PYINS_OK (0) or the first negative PYINS_E_CONFIG_* status,
    by the C core's pyins_config_check when the library is there, else by
    the reference's mirror of it (the same status: test_xcheck_config).
    ValueError for a field make_config refuses (unknown key, shape, type).
    Its text is `pyins.contract.status_str`."""
    if native is not None:
        return native.lib.pyins_config_check(native.make_config(fields))
    return reference.c_api.pyins_config_check(reference.c_api.make_config(fields))


def firmware(engine, config):
    """A firmware instance of ``engine`` from a configuration dict."""
    if check(engine) == "native":
        return _native().Firmware(config)
    return reference.Firmware(config)


def plant(engine, table, errors, record_dtype, alpha0=0.0):
    """The closed loop's plant of ``engine``: ``table`` a TableConfig,
    ``errors`` the plant's error matrices (turntable.error_matrices)."""
    if check(engine) == "native":
        return _native().Plant(table, errors, record_dtype, alpha0)
    return MirrorPlant(table, errors, record_dtype, alpha0)


class MirrorPlant:
    """`pyins.native.Plant`'s contract over the NumPy plant mirror: one
    ``turntable.plant_tick`` and one firmware ``step`` per tick, in the order
    of ``pyins_fil_run`` (csrc/plant/plant.cpp)."""

    def __init__(self, table, errors, record_dtype, alpha0=0.0):
        self._table, self._errors, self._record_dtype = table, errors, record_dtype
        self._st = turntable.PlantState(alpha_rad=float(alpha0))

    def run(self, fw, omega, force, x, w, period, phase0, gyro_noise, accel_noise, n, dt, every, sums=None):
        """As `pyins.native.Plant.run` (``sums`` is the compiled plant's shortcut
        for a table at rest: this mirror sums the nodes at every tick, in the
        order the sums were made, so the bits are the same without it)."""
        st = self._st
        tick0 = st.tick
        outs, recs = [], []
        for k in range(n):
            # 1. the plant: motor, turning IMU, sensor errors, encoder
            b = (phase0 + k) % period
            g, a, enc, seq = turntable.plant_tick(
                self._table, st, self._errors, omega[b], force[b], x, w,
                None if gyro_noise is None else gyro_noise[k],
                None if accel_noise is None else accel_noise[k], dt)
            # 2. the firmware's tick, and its motor command back to the plant
            try:
                out = fw.step(g, a, enc, seq)
            except contract.SampleError as exc:
                raise contract.PlantError(exc.code, f"pyins_fil_run at tick {tick0 + k}", k,
                                          self._kept(outs, contract.OUTPUT_DTYPE),
                                          self._kept(recs, self._record_dtype)) from None
            st.rate_cmd_rad_s = float(out["motor_rate_cmd_rad_s"])
            # 3. the kept records
            if st.tick % every == 0:
                outs.append(out)
                recs.append((st.tick, st.alpha_rad, st.rate_rad_s, enc))
        return self._kept(outs, contract.OUTPUT_DTYPE), self._kept(recs, self._record_dtype)

    @staticmethod
    def _kept(rows, dtype):
        return np.array(rows, dtype=dtype) if rows else np.zeros(0, dtype=dtype)

    def snapshot(self):
        """The plant state as bytes (JSON: exact for every float)."""
        st = self._st
        return json.dumps(dict(tick=st.tick, alpha_rad=st.alpha_rad, rate_rad_s=st.rate_rad_s,
                               rate_cmd_rad_s=st.rate_cmd_rad_s,
                               gyro_residual=list(map(float, st.gyro_residual)),
                               accel_residual=list(map(float, st.accel_residual)))).encode()

    def restore(self, blob):
        d = json.loads(bytes(blob).decode())
        self._st = turntable.PlantState(
            tick=d["tick"], alpha_rad=d["alpha_rad"], rate_rad_s=d["rate_rad_s"],
            rate_cmd_rad_s=d["rate_cmd_rad_s"], gyro_residual=np.array(d["gyro_residual"]),
            accel_residual=np.array(d["accel_residual"]))
