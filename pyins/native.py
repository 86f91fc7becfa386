"""cffi (ABI mode) binding of the built firmware core (`Firmware`) and of the
compiled closed-loop plant (`Plant`, ``libpyins_plant.so``).

The library ``libpyins_core.so`` and its headers are installed inside the
``pyins`` package by ``pip install .``; the cdef is read from the installed
``pyins_core.h`` (see ``pyins._cdef``), and the library's ABI version and
struct sizes are checked at import, so a stale build fails loudly here and
not later with corrupted memory.

``PYINS_CORE_LIB=/path/to/libpyins_core.so`` loads another build (its
headers are taken from beside it, else from the source tree).
"""
import importlib.resources
import os
from pathlib import Path

import cffi
import numpy as np

from ._cdef import read_cdef

#: The ABI this Python code was written against: (major, minor).
EXPECTED_ABI = (0, 13)

_LIB_NAME = "libpyins_core.so"
_HEADERS = ("pyins_core.h", "pyins_core_testing.h", "pyins_plant.h")
_PLANT_NAME = "libpyins_plant.so"
_REBUILD = "run `pip install .` (or `bash tools/setup.sh`) in the pyins source tree to build it"


def _package_file(name):
    return importlib.resources.files("pyins") / name


def _locate():
    """Paths (library, {header name: header text})."""
    override = os.environ.get("PYINS_CORE_LIB")
    lib_path = Path(override) if override else _package_file(_LIB_NAME)
    if not lib_path.is_file():
        where = f"PYINS_CORE_LIB={override}" if override else "inside the installed pyins package"
        raise ImportError(f"pyins: the firmware core library {_LIB_NAME} was not found {where}; {_REBUILD}.")
    texts = {}
    source = Path(__file__).resolve().parent.parent / "csrc"
    for name in _HEADERS:
        candidates = [Path(str(lib_path)).parent / name] if override else [_package_file(name)]
        candidates.append(source / ("plant" if name == "pyins_plant.h" else "include") / name)
        for c in candidates:
            if c.is_file():
                texts[name] = c.read_text()
                break
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
                       ("pyins_output", lib.pyins_sizeof_output)):
        if ffi.sizeof(struct) != fn():
            raise ImportError(f"pyins: struct {struct} is {fn()} bytes in {lib_path} but "
                              f"{ffi.sizeof(struct)} bytes in its header; {_REBUILD}.")
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

_PRIMITIVE = {"double": "<f8", "int64_t": "<i8", "int32_t": "<i4", "uint32_t": "<u4",
              "uint64_t": "<u8", "uint8_t": "u1"}


def _numpy_dtype(struct_name):
    """The NumPy dtype with exactly the C struct's layout (names, offsets, size)."""
    t = ffi.typeof(struct_name)
    names, formats, offsets = [], [], []
    for name, field in t.fields:
        ft = field.type
        if ft.kind == "array":
            formats.append((np.dtype(_PRIMITIVE[ft.item.cname]), (ft.length,)))
        else:
            formats.append(np.dtype(_PRIMITIVE[ft.cname]))
        names.append(name)
        offsets.append(field.offset)
    return np.dtype({"names": names, "formats": formats, "offsets": offsets,
                     "itemsize": ffi.sizeof(t)})


SAMPLE_DTYPE = _numpy_dtype("pyins_sample")
#: Statuses that reject a sample (batch calls stop there; SampleError).
_SAMPLE_REJECTED = (lib.PYINS_E_SAMPLE_NONFINITE, lib.PYINS_E_SAMPLE_SATURATED)
OUTPUT_DTYPE = _numpy_dtype("pyins_output")
#: The compact record (pyins_nav): OUTPUT_DTYPE's fields of the same names.
NAV_DTYPE = _numpy_dtype("pyins_nav")
CONFIG_FIELDS = tuple(name for name, _ in ffi.typeof("pyins_config").fields)

VERTICAL_MODES = {"hold": 0, "free": 1}


class CoreError(RuntimeError):
    """A negative pyins_status returned by the C core."""

    def __init__(self, code, where):
        self.code = code
        self.status_name = status_str(code).split(":")[0]
        super().__init__(f"{where}: {status_str(code)}")


class ConfigError(CoreError, ValueError):
    """The core refused a configuration."""


class SampleError(CoreError, ValueError):
    """The core rejected a sample (NaN/Inf, or an increment at or beyond its
    saturation limit); ``index`` is its position, ``outputs`` the records of
    the samples handled before it (the state is after those)."""

    def __init__(self, code, index, outputs):
        self.index = index
        self.outputs = outputs
        super().__init__(code, f"sample {index} rejected ({index} samples before it were "
                               f"accepted; the state is after them)")


class SnapshotError(CoreError, ValueError):
    """The core refused a snapshot blob; the state was left as it was."""


def status_str(code):
    return ffi.string(lib.pyins_status_str(int(code))).decode()


def _as_float_array(name, value, tail, contiguous=True):
    """Check one input array: float64, shape (N,) + tail, C-contiguous
    (unless ``contiguous`` is False: the caller copies it).

    Plain Python sequences are converted; NumPy arrays must already be right
    (cffi's from_buffer would reinterpret a wrong dtype silently).
    """
    if isinstance(value, np.ndarray):
        a = value
    else:
        try:
            a = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{name}: cannot be read as float64 numbers ({exc})") from None
    if a.dtype != np.float64:
        raise ValueError(f"{name}: dtype is {a.dtype}, expected float64 "
                         f"(convert with .astype(numpy.float64))")
    want = "(N,)" if not tail else f"(N, {', '.join(map(str, tail))})"
    if a.ndim != 1 + len(tail) or a.shape[1:] != tail:
        raise ValueError(f"{name}: shape is {a.shape}, expected {want}")
    if contiguous and not a.flags.c_contiguous:
        raise ValueError(f"{name}: array is not C-contiguous (use numpy.ascontiguousarray)")
    return a


def make_samples(dtheta_p_rad, dv_p_mps, table_angle_rad=None, seq=None):
    """Pack per-field arrays into a SAMPLE_DTYPE array, checking each field.

    dtheta_p_rad, dv_p_mps: (N, 3) float64 [rad], [m/s]; table_angle_rad:
    (N,) float64 [rad] or None for a table fixed at 0; seq: (N,) integers,
    the IMU's sample counter (taken modulo 2^32), or None for zeros. The core
    reads seq only with ``seq_mode=1`` (PYINS_SEQ_CHECK) in its configuration;
    logs without a counter leave it off. The fields are copied, so views
    (a column slice of a log, every other row) are fine.
    """
    dtheta = _as_float_array("dtheta_p_rad", dtheta_p_rad, (3,), contiguous=False)
    dv = _as_float_array("dv_p_mps", dv_p_mps, (3,), contiguous=False)
    n = dtheta.shape[0]
    if dv.shape[0] != n:
        raise ValueError(f"dv_p_mps: has {dv.shape[0]} rows but dtheta_p_rad has {n}")
    samples = np.zeros(n, dtype=SAMPLE_DTYPE)
    samples["dtheta_p_rad"] = dtheta
    samples["dv_p_mps"] = dv
    if table_angle_rad is not None:
        table = _as_float_array("table_angle_rad", table_angle_rad, (), contiguous=False)
        if table.shape[0] != n:
            raise ValueError(f"table_angle_rad: has {table.shape[0]} rows but dtheta_p_rad has {n}")
        samples["table_angle_rad"] = table
    if seq is not None:
        counter = np.asarray(seq)
        if counter.shape != (n,) or not np.issubdtype(counter.dtype, np.integer):
            raise ValueError(f"seq: expected {n} integers, got dtype {counter.dtype} shape {counter.shape}")
        samples["seq"] = counter.astype(np.int64) & 0xFFFFFFFF   # modulo 2^32, as the IMU's counter wraps
    return samples


def _check_samples(samples):
    if (type(samples) is np.ndarray and samples.dtype is SAMPLE_DTYPE and samples.ndim == 1
            and samples.flags.c_contiguous):
        return samples          # the common case, checked in a few hundred ns
    if not isinstance(samples, np.ndarray) or samples.dtype != SAMPLE_DTYPE:
        got = samples.dtype if isinstance(samples, np.ndarray) else type(samples).__name__
        raise ValueError(f"samples: expected an array of pyins.native.SAMPLE_DTYPE, got {got} "
                         f"(build one with pyins.native.make_samples)")
    if samples.ndim != 1:
        raise ValueError(f"samples: shape is {samples.shape}, expected (N,)")
    if not samples.flags.c_contiguous:
        raise ValueError("samples: array is not C-contiguous (use numpy.ascontiguousarray)")
    return samples


def make_config(config=None, **fields):
    """A ``pyins_config *`` from a dict and/or keywords named like the C fields.

    Starts from the defaults; unknown keys raise ValueError. ``vertical_mode``
    takes 'hold', 'free' or the integer value.
    """
    merged = dict(config or {})
    merged.update(fields)
    cfg = ffi.new("pyins_config *")
    lib.pyins_config_default(cfg)
    for key, value in merged.items():
        if key not in CONFIG_FIELDS:
            raise ValueError(f"config: unknown key {key!r} (known: {', '.join(CONFIG_FIELDS)})")
        if key == "vertical_mode" and isinstance(value, str):
            if value not in VERTICAL_MODES:
                raise ValueError(f"config: vertical_mode {value!r} is not one of {sorted(VERTICAL_MODES)}")
            value = VERTICAL_MODES[value]
        current = getattr(cfg, key)
        if key == "index_steps":
            steps = list(value)
            if len(steps) > len(current):
                raise ValueError(f"config: index_steps holds at most {len(current)} steps, got {len(steps)}")
            for i, step in enumerate(steps):
                try:
                    stop, kind, angle = (step["stop_ticks"], step["kind"], step["angle_rad"]) \
                        if isinstance(step, dict) else step
                    current[i].stop_ticks, current[i].kind, current[i].angle_rad = stop, kind, angle
                except (TypeError, ValueError, KeyError, OverflowError) as exc:
                    raise ValueError(f"config: index_steps[{i}] must be (stop_ticks, kind, angle_rad): "
                                     f"{exc}") from None
            continue
        if isinstance(current, ffi.CData):   # a fixed-length array field
            arr = np.asarray(value, dtype=np.float64)
            if arr.shape != (len(current),):
                raise ValueError(f"config: {key} needs {len(current)} values, got shape {arr.shape}")
            for i, v in enumerate(arr):
                current[i] = float(v)
        else:
            try:
                setattr(cfg, key, value)
            except (TypeError, OverflowError) as exc:
                raise ValueError(f"config: {key}={value!r}: {exc}") from None
    return cfg


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
        self.config = {name: getattr(cfg, name) for name in CONFIG_FIELDS
                       if not isinstance(getattr(cfg, name), ffi.CData)}

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


class PlantError(CoreError):
    """``pyins_fil_run`` stopped at a rejected sample: ``outputs`` and
    ``records`` are the kept records before it, ``n_done`` the ticks done."""

    def __init__(self, code, where, n_done, outputs, records):
        self.n_done, self.outputs, self.records = n_done, outputs, records
        super().__init__(code, where)


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

    def run(self, fw, omega, force, x, w, period, phase0, gyro_noise, accel_noise, n, dt, every):
        """``n`` ticks of the closed loop around ``fw`` (a `Firmware`).

        omega, force: the ship's body rate and specific force at the
        quadrature nodes (x, w) of ``period`` ticks, starting at phase
        ``phase0`` (tiled when the motion repeats); gyro_noise, accel_noise:
        (n, 3) white-noise increments or None. Returns (outputs, records) at
        the ticks that are multiples of ``every``; PlantError at a rejected
        sample.
        """
        omega, force = np.ascontiguousarray(omega), np.ascontiguousarray(force)
        x, w = np.ascontiguousarray(x), np.ascontiguousarray(w)
        g_ptr = ffi.NULL if gyro_noise is None else ffi.from_buffer("double[]", gyro_noise)
        a_ptr = ffi.NULL if accel_noise is None else ffi.from_buffer("double[]", accel_noise)
        cap = n // every + 1
        out = np.empty(cap, dtype=OUTPUT_DTYPE)
        rec = np.empty(cap, dtype=self._record_dtype)
        tick0 = self._st.tick
        status = plant.pyins_fil_run(
            fw.core, self._st, self._tab, self._err, ffi.from_buffer("double[]", omega),
            ffi.from_buffer("double[]", force), ffi.from_buffer("double[]", x),
            ffi.from_buffer("double[]", w), len(x), period, phase0, g_ptr, a_ptr, n, dt, every,
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
