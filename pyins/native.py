"""cffi (ABI mode) binding of the built firmware core (`Firmware`) and of the
compiled closed-loop plant (`Plant`, ``libpyins_plant.so``).

The library ``libpyins_core.so`` and its headers are installed inside the
``pyins`` package by ``pip install .``; the cdef is read from the installed
``pyins_core.h`` (see ``pyins._cdef``), and the library's ABI version and
struct sizes are checked at import, so a stale build fails loudly here and
not later with corrupted memory.

``PYINS_CORE_LIB=/path/to/libpyins_core.so`` loads another build (its
headers are taken from beside it, else from the source tree).

The ABI's data contract (the record dtypes, CONFIG_FIELDS, the errors,
make_samples, the status texts) lives in `pyins.contract`, which needs no
library; it is re-exported here under the same names (the same objects).
This module adds what needs the library: the dlopen and its checks,
``make_config`` (the C defaults, ``pyins_config_default``), `Firmware`,
`Plant` and the library's own ``status_str``.
"""
import importlib.resources
import os
from pathlib import Path

import cffi
import numpy as np

from . import contract
from ._cdef import read_cdef

#: The ABI this Python code was written against: (major, minor).
EXPECTED_ABI = (0, 20)

_LIB_NAME = "libpyins_core.so"
_HEADERS = ("pyins_core.h", "pyins_core_testing.h", "pyins_plant.h")
_PLANT_NAME = "libpyins_plant.so"
_REBUILD = "run `pip install .` (or `bash tools/setup.sh`) in the pyins source tree to build it"


def _package_file(name):
    return importlib.resources.files("pyins") / name


def _locate():
    """Paths (library, {header name: header text}); the headers as
    `pyins.contract.find_header` finds them (beside an overriding library,
    else inside the package, then the source tree)."""
    override = os.environ.get("PYINS_CORE_LIB")
    lib_path = Path(override) if override else _package_file(_LIB_NAME)
    if not lib_path.is_file():
        where = f"PYINS_CORE_LIB={override}" if override else "inside the installed pyins package"
        raise ImportError(f"pyins: the firmware core library {_LIB_NAME} was not found {where}; {_REBUILD}.")
    texts = {}
    for name in _HEADERS:
        found = contract.find_header(name, Path(str(lib_path)).parent if override else None)
        if found is not None:
            texts[name] = found[1]
    if "pyins_core.h" not in texts:
        raise ImportError(f"pyins: pyins_core.h was not found next to {lib_path}; {_REBUILD}.")
    return lib_path, texts


def _load():
    lib_path, texts = _locate()
    ffi = cffi.FFI()
    ffi.cdef(read_cdef(texts["pyins_core.h"]))
    has_hooks = "pyins_core_testing.h" in texts
    if has_hooks:
        ffi.cdef(read_cdef(texts["pyins_core_testing.h"]))
    try:
        lib = ffi.dlopen(str(lib_path))
    except OSError as exc:
        raise ImportError(f"pyins: cannot load {lib_path}: {exc}; {_REBUILD}.") from exc
    try:
        abi = lib.pyins_abi_version()
    except AttributeError as exc:
        raise ImportError(f"pyins: {lib_path} is not a pyins core library; {_REBUILD}.") from exc
    got = (abi >> 16, abi & 0xFFFF)
    if got != EXPECTED_ABI:
        raise ImportError(f"pyins: the core library {lib_path} has ABI {got[0]}.{got[1]} but this "
                          f"pyins expects {EXPECTED_ABI[0]}.{EXPECTED_ABI[1]}; {_REBUILD}.")
    for struct, fn in (("pyins_config", lib.pyins_sizeof_config),
                       ("pyins_sample", lib.pyins_sizeof_sample),
                       ("pyins_output", lib.pyins_sizeof_output),
                       ("pyins_nav", lib.pyins_sizeof_nav)):
        if ffi.sizeof(struct) != fn():
            raise ImportError(f"pyins: struct {struct} is {fn()} bytes in {lib_path} but "
                              f"{ffi.sizeof(struct)} bytes in its header; {_REBUILD}.")
    for struct, dtype in (("pyins_sample", contract.SAMPLE_DTYPE), ("pyins_output", contract.OUTPUT_DTYPE),
                          ("pyins_nav", contract.NAV_DTYPE)):
        if contract.struct_dtype(struct, ffi) != dtype:
            raise ImportError(f"pyins: struct {struct} of the header beside {lib_path} is not the one "
                              f"pyins.contract read ({contract.HEADER_PATH}); {_REBUILD}.")
    if has_hooks:
        try:
            lib.pyins_t_sin  # noqa: B018  (the library may be built without hooks)
        except AttributeError:
            has_hooks = False
    plant = None
    plant_path = Path(str(lib_path)).parent / _PLANT_NAME
    if "pyins_plant.h" in texts and plant_path.is_file():
        ffi.cdef(read_cdef(texts["pyins_plant.h"]))
        plant = ffi.dlopen(str(plant_path))
    return ffi, lib, lib_path, has_hooks, plant


ffi, lib, LIBRARY_PATH, HAS_TEST_HOOKS, plant = _load()

# The ABI's data contract (pyins.contract), re-exported under its old names:
# the same objects, so `except native.SampleError` catches either engine's.
SAMPLE_DTYPE = contract.SAMPLE_DTYPE
OUTPUT_DTYPE = contract.OUTPUT_DTYPE
NAV_DTYPE = contract.NAV_DTYPE
REF_DTYPE = contract.REF_DTYPE
CONFIG_FIELDS = contract.CONFIG_FIELDS
VERTICAL_MODES = contract.VERTICAL_MODES
CoreError = contract.CoreError
ConfigError = contract.ConfigError
SampleError = contract.SampleError
SnapshotError = contract.SnapshotError
RefError = contract.RefError
PlantError = contract.PlantError
make_samples = contract.make_samples
_SAMPLE_REJECTED = contract.SAMPLE_REJECTED
_as_float_array = contract.as_float_array
_check_samples = contract.check_samples


def _numpy_dtype(struct_name):
    """The NumPy dtype with exactly the C struct's layout (of this binding's ffi)."""
    return contract.struct_dtype(struct_name, ffi)


def status_str(code):
    """The library's own pyins_status_str (contract.status_str is its text
    without the library)."""
    return ffi.string(lib.pyins_status_str(int(code))).decode()


def make_config(config=None, **fields):
    """A ``pyins_config *`` from a dict and/or keywords named like the C fields.

    Starts from the defaults; unknown keys raise ValueError. ``vertical_mode``
    takes 'hold', 'free' or the integer value.
    """
    merged = dict(config or {})
    merged.update(fields)
    cfg = ffi.new("pyins_config *")
    lib.pyins_config_default(cfg)
    return contract.set_config_fields(cfg, merged)


class Firmware:
    """One firmware instance in memory owned by this object.

    >>> fw = Firmware(lat_rad=0.5, euler_b_rad=[0, 0, 1.0])
    >>> out = fw.run(make_samples(dtheta, dv))      # doctest: +SKIP
    """

    def __init__(self, config=None, **fields):
        cfg = make_config(config, **fields)
        self._setup_memory()
        status = lib.pyins_init(self._core, lib.pyins_core_size(), cfg)
        if status != 0:
            raise ConfigError(status, "pyins_init")
        self.config = contract.scalar_config(cfg)

    def _setup_memory(self):
        size = lib.pyins_core_size()
        align = lib.pyins_core_align()
        self._mem = ffi.new("unsigned char[]", size + align)
        addr = int(ffi.cast("uintptr_t", self._mem))
        self._core = ffi.cast("pyins_core *", self._mem + (-addr) % align)
        self._one_out = np.zeros(1, dtype=OUTPUT_DTYPE)
        self._one_out_ptr = ffi.cast("pyins_output *", ffi.from_buffer(self._one_out))
        self._one_sample = np.zeros(1, dtype=SAMPLE_DTYPE)
        self._one_sample_ptr = ffi.cast("pyins_sample *", ffi.from_buffer(self._one_sample))
        self._n_done = ffi.new("size_t *")
        self.last_status = 0

    def _run_decimated(self, samples, every, compact=False):
        if every < 1:
            raise ValueError(f"every: must be a positive number of ticks, got {every}")
        if compact:
            call, name, dtype, ctype = lib.pyins_run_nav, "pyins_run_nav", NAV_DTYPE, "pyins_nav *"
        else:
            call, name, dtype, ctype = (lib.pyins_run_decimated, "pyins_run_decimated", OUTPUT_DTYPE,
                                        "pyins_output *")
        n = samples.shape[0]
        n_done = ffi.new("size_t *")
        n_out = ffi.new("size_t *")
        parts = []
        start = 0
        while True:
            rest = samples[start:]
            capacity = (n - start) // every + 1
            outputs = np.empty(capacity, dtype=dtype)
            status = call(
                self._core, ffi.cast("pyins_sample *", ffi.from_buffer(rest)), n - start, every,
                ffi.cast(ctype, ffi.from_buffer(outputs, require_writable=True)), capacity,
                n_done, n_out)
            parts.append(outputs[: n_out[0]])
            start += int(n_done[0])
            # seq gaps can pass more multiples of `every` than the samples
            # count: the call stops before overflowing; go on with a new buffer
            if status == lib.PYINS_E_BUFFER_TOO_SMALL and n_out[0] == capacity:
                continue
            break
        records = parts[0] if len(parts) == 1 else np.concatenate(parts)
        if status != 0:
            if status in _SAMPLE_REJECTED:
                raise SampleError(status, start, records.copy())
            raise CoreError(status, name)
        return records

    def run_nav(self, samples, every=1):
        """As ``run``, with the compact record: a NAV_DTYPE array, one record
        after each step whose tick is a multiple of ``every`` (1: every
        step that advances the tick). Its fields are OUTPUT_DTYPE's of the
        same names, bit for bit, at less than a fifth of a full record's
        cost (pyins_run_nav)."""
        return self._run_decimated(_check_samples(samples), int(every), compact=True)

    def nav(self):
        """The current state as one NAV_DTYPE record (pyins_get_nav)."""
        rec = np.zeros(1, dtype=NAV_DTYPE)
        status = lib.pyins_get_nav(self._core, ffi.cast("pyins_nav *", ffi.from_buffer(rec, require_writable=True)))
        if status != 0:
            raise CoreError(status, "pyins_get_nav")
        return rec[0].copy()

    def snapshot(self):
        """The whole firmware state as a versioned, checksummed blob (bytes)."""
        buf = ffi.new("unsigned char[]", lib.pyins_snapshot_size())
        status = lib.pyins_snapshot(self._core, buf, len(buf))
        if status != 0:
            raise CoreError(status, "pyins_snapshot")
        return bytes(ffi.buffer(buf))

    def restore(self, blob):
        """Replace the state with a snapshot. A truncated, corrupted,
        wrong-version or wrong-size blob raises SnapshotError and leaves the
        current state untouched."""
        if not isinstance(blob, (bytes, bytearray, memoryview)):
            raise ValueError(f"snapshot: expected bytes, got {type(blob).__name__}")
        data = ffi.from_buffer(bytes(blob))
        status = lib.pyins_restore(self._core, lib.pyins_core_size(), data, len(data))
        if status != 0:
            raise SnapshotError(status, "pyins_restore")

    @classmethod
    def from_snapshot(cls, blob):
        """A new instance holding a snapshot's state."""
        fw = cls.__new__(cls)
        fw._setup_memory()
        fw.config = {}
        fw.restore(blob)
        return fw

    def push_ref(self, refs):
        """Hand the firmware external references (a REF_DTYPE array or one
        record), in order (pyins_push_ref). RefError at the first refused:
        those before it were taken."""
        refs = contract.check_refs(refs)
        ptr = ffi.cast("pyins_ref *", ffi.from_buffer(refs))
        for i in range(refs.shape[0]):
            status = lib.pyins_push_ref(self._core, ptr + i)
            if status != 0:
                raise RefError(status, i)

    def index_reset(self):
        """Leave the indexing FAULT state (pyins_index_reset)."""
        status = lib.pyins_index_reset(self._core)
        if status != 0:
            raise CoreError(status, "pyins_index_reset")

    @property
    def core(self):
        """The raw ``pyins_core *`` (for benchmarks and tests)."""
        return self._core

    def output(self):
        """The current state as one OUTPUT_DTYPE record."""
        status = lib.pyins_get_output(self._core, self._one_out_ptr)
        if status != 0:
            raise CoreError(status, "pyins_get_output")
        return self._one_out[0].copy()

    def step(self, dtheta_p_rad, dv_p_mps, table_angle_rad=0.0, seq=0):
        """One tick; returns its OUTPUT_DTYPE record. SampleError if rejected.

        A PYINS_W_* notice (a bridged gap, a dropped duplicate, ...) is kept
        in ``last_status``; the record's fault bits and counters show it too.
        """
        s = self._one_sample
        s["dtheta_p_rad"][0] = _as_float_array("dtheta_p_rad", np.atleast_2d(dtheta_p_rad), (3,))[0]
        s["dv_p_mps"][0] = _as_float_array("dv_p_mps", np.atleast_2d(dv_p_mps), (3,))[0]
        s["table_angle_rad"][0] = float(table_angle_rad)
        s["seq"][0] = int(seq) & 0xFFFFFFFF
        status = lib.pyins_step(self._core, self._one_sample_ptr, self._one_out_ptr)
        self.last_status = status
        if status < 0:
            raise SampleError(status, 0, np.zeros(0, dtype=OUTPUT_DTYPE))
        return self._one_out[0].copy()

    def run(self, samples, outputs=None, every=1):
        """Step through a SAMPLE_DTYPE array in one C call.

        Returns the OUTPUT_DTYPE array: one record per sample, or with
        ``every=k`` one record after each step whose tick is a multiple of k
        (``every=100``: 1 Hz records at 100 Hz, in phase across calls).
        ``outputs`` may be a preallocated array to fill (every=1 only).
        SampleError at the first rejected sample, carrying the records before
        it; sample-level notices (seq gaps, duplicates, encoder jumps) do not
        stop the run: see the records' ``fault_flags`` and ``n_*`` counters.
        """
        samples = _check_samples(samples)
        n = samples.shape[0]
        if every != 1:
            return self._run_decimated(samples, int(every))
        if outputs is None:
            outputs = np.empty(n, dtype=OUTPUT_DTYPE)
        elif (not isinstance(outputs, np.ndarray) or outputs.dtype != OUTPUT_DTYPE
              or outputs.shape != (n,) or not outputs.flags.c_contiguous
              or not outputs.flags.writeable):
            raise ValueError("outputs: expected a writeable C-contiguous OUTPUT_DTYPE array "
                             f"of shape ({n},)")
        n_done = self._n_done
        status = lib.pyins_run(self._core, ffi.from_buffer("pyins_sample[]", samples), n,
                               ffi.from_buffer("pyins_output[]", outputs, require_writable=True),
                               n_done)
        if status != 0:
            if status in _SAMPLE_REJECTED:
                raise SampleError(status, int(n_done[0]), outputs[: n_done[0]].copy())
            raise CoreError(status, "pyins_run")
        return outputs


class Plant:
    """The compiled plant (``libpyins_plant.so``, csrc/plant): the turntable's
    motor and encoder and the IMU's sensor errors around one `Firmware`,
    tick by tick (``pyins_fil_run``).

    ``table`` holds the pyins_table_config fields (a
    ``pyins.sim.turntable.TableConfig``), ``errors`` the plant's error
    matrices (``pyins.sim.turntable.error_matrices``), ``alpha0`` the table
    angle at the start [rad]. ``record_dtype`` is the NumPy twin of
    ``pyins_plant_record``, given by the caller (pyins.records).
    """

    def __init__(self, table, errors, record_dtype, alpha0=0.0):
        if plant is None:
            raise RuntimeError("the plant library libpyins_plant.so is not installed; run `pip install .`")
        self._st = ffi.new("pyins_plant_state *")
        self._st.alpha_rad = alpha0
        self._err = ffi.new("pyins_imu_errors *")
        for i in range(9):
            self._err.gyro_m[i] = errors["gyro_m"].ravel()[i]
            self._err.accel_m[i] = errors["accel_m"].ravel()[i]
        for i in range(3):
            self._err.gyro_bias_rad_s[i] = errors["gyro_bias"][i]
            self._err.accel_bias_mps2[i] = errors["accel_bias"][i]
        self._err.gyro_quantum_rad = errors["gyro_quantum"]
        self._err.accel_quantum_mps = errors["accel_quantum"]
        self._tab = ffi.new("pyins_table_config *")
        t = self._tab
        t.rate_max_rad_s, t.accel_max_rad_s2 = table.rate_max_rad_s, table.accel_max_rad_s2
        t.encoder_lsb_rad, t.jump_rad = table.encoder_lsb_rad, table.jump_rad
        t.fault_tick, t.fault = table.fault_tick, table.fault
        self._record_dtype = record_dtype
        self._n_done = ffi.new("size_t *")
        self._n_out = ffi.new("size_t *")

    def run(self, fw, omega, force, x, w, period, phase0, gyro_noise, accel_noise, n, dt, every, sums=None):
        """``n`` ticks of the closed loop around ``fw`` (a `Firmware`).

        omega, force: the ship's body rate and specific force at the
        quadrature nodes (x, w) of ``period`` ticks, starting at phase
        ``phase0`` (tiled when the motion repeats); gyro_noise, accel_noise:
        (n, 3) white-noise increments or None; ``sums``: None or
        `pyins.sim.node_sums` of omega, force (period, 3) each, which a tick
        with the table at rest then reads instead of summing its nodes (the
        same bits). Returns (outputs, records) at the ticks that are
        multiples of ``every``; PlantError at a rejected sample.
        """
        omega, force = np.ascontiguousarray(omega), np.ascontiguousarray(force)
        x, w = np.ascontiguousarray(x), np.ascontiguousarray(w)
        if sums is None:
            s_omega = s_force = ffi.NULL
        else:
            if sums[0].shape != (period, 3) or sums[1].shape != (period, 3):
                raise ValueError(f"Plant.run: the node sums must be ({period}, 3) each")
            s_omega = ffi.from_buffer("double[]", np.ascontiguousarray(sums[0], dtype=np.float64))
            s_force = ffi.from_buffer("double[]", np.ascontiguousarray(sums[1], dtype=np.float64))
        g_ptr = ffi.NULL if gyro_noise is None else ffi.from_buffer("double[]", gyro_noise)
        a_ptr = ffi.NULL if accel_noise is None else ffi.from_buffer("double[]", accel_noise)
        cap = n // every + 1
        out = np.empty(cap, dtype=OUTPUT_DTYPE)
        rec = np.empty(cap, dtype=self._record_dtype)
        tick0 = self._st.tick
        status = plant.pyins_fil_run(
            fw.core, self._st, self._tab, self._err, ffi.from_buffer("double[]", omega),
            ffi.from_buffer("double[]", force), ffi.from_buffer("double[]", x),
            ffi.from_buffer("double[]", w), s_omega, s_force, len(x), period, phase0, g_ptr, a_ptr, n, dt,
            every,
            ffi.from_buffer("pyins_output[]", out, require_writable=True),
            ffi.cast("pyins_plant_record *", ffi.from_buffer(rec, require_writable=True)), cap,
            self._n_done, self._n_out)
        kept = self._n_out[0]
        if status != 0:
            raise PlantError(status, f"pyins_fil_run at tick {tick0 + self._n_done[0]}",
                             int(self._n_done[0]), out[:kept].copy(), rec[:kept].copy())
        return out[:kept], rec[:kept]

    def snapshot(self):
        """The plant state as raw bytes (restore on the machine kind that wrote it)."""
        return bytes(ffi.buffer(self._st, ffi.sizeof("pyins_plant_state")))

    def restore(self, blob):
        ffi.memmove(self._st, blob, ffi.sizeof("pyins_plant_state"))


def abi_version():
    v = lib.pyins_abi_version()
    return (v >> 16, v & 0xFFFF)


def version():
    return ffi.string(lib.pyins_version_string()).decode()
