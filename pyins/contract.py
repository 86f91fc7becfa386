"""The C ABI's data contract, without the library: what the compiled core
(`pyins.native`) and its NumPy mirror (`pyins.reference`) share.

- the record and sample dtypes ``SAMPLE_DTYPE``, ``OUTPUT_DTYPE``,
  ``NAV_DTYPE``: NumPy twins of ``pyins_sample``, ``pyins_output`` and
  ``pyins_nav``, laid out from the header ``pyins_core.h`` by a cdef-only
  ``cffi.FFI`` (``ffi``; nothing is loaded);
- the configuration's field list ``CONFIG_FIELDS`` and `set_config_fields`,
  which writes a dict of fields into a ``pyins_config`` struct with the
  checks of name, shape and type both engines apply;
- the status texts of ``pyins_status_str`` (`status_str`) and the errors
  `CoreError`, `ConfigError`, `SampleError`, `RefError`, `SnapshotError`, `PlantError`;
- `make_samples` and the array checks of the engines' inputs.

The header is ``pyins_core.h`` installed inside the package (``pip install
.``), else the source tree's ``csrc/include/pyins_core.h``; with
``PYINS_CORE_LIB=/path/to/libpyins_core.so`` the one beside that library
first, as `pyins.native` reads it. `pyins.native` re-exports every name
here (the same objects: ``except native.SampleError`` catches the reference
engine's errors) and checks at import that the library's struct sizes are
this header's.
"""
import importlib.resources
import os
from pathlib import Path

import cffi
import numpy as np

from ._cdef import read_cdef

_SOURCE = Path(__file__).resolve().parent.parent / "csrc"
_HEADER_DIRS = {"pyins_plant.h": "plant"}   # else csrc/include


def find_header(name, beside=None):
    """(path, text) of a core header, or None: beside ``beside`` (a
    directory) if given, else inside the installed package; then the source
    tree's csrc/."""
    first = Path(beside) / name if beside is not None else importlib.resources.files("pyins") / name
    for candidate in (first, _SOURCE / _HEADER_DIRS.get(name, "include") / name):
        if candidate.is_file():
            return candidate, candidate.read_text()
    return None


def _override_dir():
    override = os.environ.get("PYINS_CORE_LIB")
    return Path(override).parent if override else None


def _load_header():
    found = find_header("pyins_core.h", _override_dir())
    if found is None:
        raise ImportError("pyins: the core header pyins_core.h was found neither inside the installed "
                          f"pyins package nor in the source tree ({_SOURCE / 'include'}); the record "
                          "layouts are read from it")
    return found


#: Where the header was read from.
HEADER_PATH, HEADER_TEXT = _load_header()

#: The header's declarations (types, enums, prototypes), with no library.
ffi = cffi.FFI()
ffi.cdef(read_cdef(HEADER_TEXT))

_PRIMITIVE = {"double": "<f8", "int64_t": "<i8", "int32_t": "<i4", "uint32_t": "<u4",
              "uint64_t": "<u8", "uint8_t": "u1"}


def struct_dtype(struct_name, from_ffi=ffi):
    """The NumPy dtype with exactly the C struct's layout (names, offsets,
    size) as ``from_ffi`` declares it."""
    t = from_ffi.typeof(struct_name)
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
                     "itemsize": from_ffi.sizeof(t)})


SAMPLE_DTYPE = struct_dtype("pyins_sample")
OUTPUT_DTYPE = struct_dtype("pyins_output")
#: The compact record (pyins_nav): OUTPUT_DTYPE's fields of the same names.
NAV_DTYPE = struct_dtype("pyins_nav")
#: An external reference measurement (pyins_ref), what ``push_ref`` takes.
REF_DTYPE = struct_dtype("pyins_ref")
#: The pyins_config fields, in the struct's order.
CONFIG_FIELDS = tuple(name for name, _ in ffi.typeof("pyins_config").fields)

#: Every pyins_status enumerator of the header: name -> value.
STATUSES = dict(ffi.typeof("enum pyins_status").relements)
#: Statuses that reject a sample (batch calls stop there; SampleError).
SAMPLE_REJECTED = (STATUSES["PYINS_E_SAMPLE_NONFINITE"], STATUSES["PYINS_E_SAMPLE_SATURATED"])

#: ``vertical_mode`` by name, as make_config reads it.
VERTICAL_MODES = {"hold": 0, "free": 1}

# --- pyins_status_str (csrc/src/c_api.cpp), text for text -------------------
# tests/native/test_contract.py holds every status (and an unknown code) equal
# to the library's pyins_status_str.
_STATUS_MEANING = {
    "PYINS_OK": "success",
    "PYINS_E_NULL": "a required pointer argument is NULL",
    "PYINS_E_MISALIGNED": "instance memory is not aligned to pyins_core_align()",
    "PYINS_E_MEM_TOO_SMALL": "memory is smaller than pyins_core_size()",
    "PYINS_E_NOT_INIT": "the memory does not hold an initialised instance",
    "PYINS_E_SAMPLE_NONFINITE": "a sample field is NaN or Inf; sample rejected, state unchanged",
    "PYINS_E_BAD_ARG": "an argument is out of range (e.g. out_every == 0)",
    "PYINS_E_BUFFER_TOO_SMALL": "the output buffer cannot hold the records asked for",
    "PYINS_E_CONFIG_RATE": "tick_hz must be 0 (default 100) or 1..10000",
    "PYINS_E_CONFIG_LAT": "latitude must be finite and within +-89.9 deg (ENU is singular at the poles)",
    "PYINS_E_CONFIG_LON": "longitude must be finite and within +-720 deg",
    "PYINS_E_CONFIG_HEIGHT": "height must be finite and within -1e4..1e5 m",
    "PYINS_E_CONFIG_VEL": "velocity must be finite and below 1e4 m/s per axis",
    "PYINS_E_CONFIG_ATT": "attitude angles, table angle and dvl_align_rad must be finite (dvl_align_rad at "
                          "most pi long)",
    "PYINS_E_CONFIG_MODE": "vertical_mode must be PYINS_VERTICAL_HOLD or PYINS_VERTICAL_FREE",
    "PYINS_E_CONFIG_ALIGN_RATIO": "coarse_ratio must be in (0, 1) (0 = default 1/2)",
    "PYINS_E_CONFIG_ALIGN_EARLY": "first coarse output before enough data (coarse_ratio * first output "
                                  "< output interval)",
    "PYINS_E_CONFIG_ALIGN_LONG": "TRIAD coarse alignment longer than its storage allows (255 output "
                                 "intervals; FIT has no limit)",
    "PYINS_E_CONFIG_FINE": "fine_states must be 5, 8 or 12, the update interval positive, the correction "
                           "known",
    "PYINS_E_CONFIG_NOISE": "noise densities and initial sigmas must be positive and finite (0 = default)",
    "PYINS_E_CONFIG_INDEX_SCHEME": "index_scheme is not one of the pyins_index_scheme values",
    "PYINS_E_CONFIG_INDEX_EMPTY": "a custom indexing scheme needs 1..8 steps",
    "PYINS_E_CONFIG_INDEX_RATE": "indexing rate and acceleration must be positive and finite",
    "PYINS_E_CONFIG_INDEX_DELTA": "the flexible threshold delta must be in (0, 1)",
    "PYINS_E_CONFIG_INDEX_STEP": "an indexing step (stop ticks >= 1, known kind, non-zero finite angle), "
                                 "tolerance, jump or timeout out of range",
    "PYINS_E_SNAPSHOT_SIZE": "snapshot blob truncated or of the wrong length, or buffer too small",
    "PYINS_E_SNAPSHOT_VERSION": "snapshot of another format or ABI version",
    "PYINS_E_SNAPSHOT_CORRUPT": "snapshot magic or checksum wrong",
    "PYINS_E_CONFIG_ALIGN_TICKS": "an alignment duration is negative, or the first output comes after its "
                                  "end",
    "PYINS_E_SAMPLE_SATURATED": "an increment is at or beyond its saturation limit; sample rejected, state "
                                "unchanged",
    "PYINS_E_CONFIG_SATURATION": "saturation limits must be positive and finite (0 = default 400 deg/s, "
                                 "20 g per tick)",
    "PYINS_E_CONFIG_SEQ": "seq_mode must be PYINS_SEQ_OFF or PYINS_SEQ_CHECK, seq_max_gap_ticks 1..100 "
                          "(0 = default)",
    "PYINS_E_CONFIG_INDEX_SUMS": "index_sums must be PYINS_INDEX_SUMS_STOPS or PYINS_INDEX_SUMS_ALL",
    "PYINS_E_CONFIG_LEVER": "lever_b_m, lever_p_m, dvl_lever_b_m and gnss_lever_b_m must be finite and at most 100 m long",
    "PYINS_E_CONFIG_COARSE_METHOD": "coarse_method must be PYINS_COARSE_TRIAD, PYINS_COARSE_FIT, "
                                    "PYINS_COARSE_EQ8 or PYINS_COARSE_FIT_VEL; PYINS_COARSE_FIT_VEL needs "
                                    "fine_ticks 0 and nav_mode not PYINS_NAV_UNDAMPED",
    "PYINS_E_CONFIG_INTEGRITY": "integrity_nis_window must be -1 (off), 0 (default) or positive, "
                                "integrity_nis_max and integrity_coarse_rad finite and not negative",
    "PYINS_E_CONFIG_NAV": "nav_mode must be AUTO, UNDAMPED, DAMPED or INTEGRATED, nav_every_ticks 1..10 s, "
                          "nav_gate positive and finite, nav_reject_limit >= 1, ref_max_latency_ticks "
                          "1..10 s (0 = default); nav_gyro_bias_rw 0..1e-6 rad/s/sqrt(s), "
                          "nav_table_scale_sigma, nav_table_mis_sigma, nav_level_scale_sigma and nav_level_mis_sigma "
                          "0..0.01 (0 = not modelled)",
    "PYINS_E_REF_KIND": "unknown reference kind, or one this build does not use (GNSS_POS, GNSS_VEL, "
                        "SPEED_LOG, DVL bottom track, ZERO_VEL are used; a DVL with reserved != 0, water "
                        "track, is not)",
    "PYINS_E_REF_VALUE": "a reference value is not finite (or a latitude beyond 90 deg), or its sigma is "
                         "not finite and > 0; refused, state unchanged",
    "PYINS_E_REF_ORDER": "a reference older than the last one pushed, or older than ref_max_latency_ticks "
                         "before the current tick; refused, state unchanged",
    "PYINS_E_REF_FUTURE": "a reference more than 10 s ahead of the current tick; refused, state unchanged",
    "PYINS_E_REF_FULL": "the reference queue (8) is full: step the samples its references wait for first; "
                        "refused, state unchanged",
    "PYINS_E_REF_UNUSED": "nav_mode is UNDAMPED (the firmware takes no references) or DAMPED (it takes no GNSS position)",
    "PYINS_W_SEQ_GAP": "ticks missing before this sample: bridged (navigation) or alignment restarted; "
                       "sample taken",
    "PYINS_W_SEQ_REPEAT": "a sample already taken (seq repeated or behind): dropped, state unchanged",
    "PYINS_W_SEQ_LOST": "seq jumped beyond the bridgeable gap: sample taken without bridging, sequence "
                        "resynchronised",
    "PYINS_W_ENCODER_JUMP": "the encoder changed by more than index_jump_rad per tick; sample taken",
}
_UNKNOWN_STATUS = "unknown pyins status code"
#: value -> "NAME: meaning", the text pyins_status_str returns. A status of
#: the header without a text here still has its name (and fails
#: test_contract's comparison with the library until it is given one).
STATUS_TEXT = {value: f"{name}: {_STATUS_MEANING.get(name, '(no text in pyins.contract)')}"
               for name, value in STATUSES.items()}


def status_str(code):
    """pyins_status_str's text for ``code``, without the library."""
    return STATUS_TEXT.get(int(code), _UNKNOWN_STATUS)


# --- the errors --------------------------------------------------------------
class CoreError(RuntimeError):
    """A negative pyins_status returned by the core (either engine)."""

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


class RefError(CoreError, ValueError):
    """The core refused a reference (``push_ref``): ``index`` is its position
    in the array pushed; those before it were taken, the state is after them."""

    def __init__(self, code, index):
        self.index = index
        super().__init__(code, f"reference {index} refused ({index} before it were taken)")


class SnapshotError(CoreError, ValueError):
    """The core refused a snapshot blob; the state was left as it was."""


class PlantError(CoreError):
    """``pyins_fil_run`` (or its NumPy mirror) stopped at a rejected sample:
    ``outputs`` and ``records`` are the kept records before it, ``n_done``
    the ticks done."""

    def __init__(self, code, where, n_done, outputs, records):
        self.n_done, self.outputs, self.records = n_done, outputs, records
        super().__init__(code, where)


# --- the configuration's fields ---------------------------------------------
def set_config_fields(cfg, fields):
    """Write ``fields`` (a dict named like the C fields) into ``cfg``, a
    ``pyins_config *`` of any FFI holding this header's declarations.

    Unknown keys, wrong shapes and values the C type cannot hold raise
    ValueError; ``vertical_mode`` takes 'hold', 'free' or the integer
    value; ``index_steps`` a sequence of (stop_ticks, kind, angle_rad) or
    dicts of those keys. Fields not named keep what ``cfg`` held.
    """
    for key, value in fields.items():
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


def scalar_config(cfg):
    """The scalar fields of a ``pyins_config *`` as a dict (an engine's
    ``config`` attribute)."""
    return {name: getattr(cfg, name) for name in CONFIG_FIELDS
            if not isinstance(getattr(cfg, name), ffi.CData)}


# --- the input arrays --------------------------------------------------------
def as_float_array(name, value, tail, contiguous=True):
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
    dtheta = as_float_array("dtheta_p_rad", dtheta_p_rad, (3,), contiguous=False)
    dv = as_float_array("dv_p_mps", dv_p_mps, (3,), contiguous=False)
    n = dtheta.shape[0]
    if dv.shape[0] != n:
        raise ValueError(f"dv_p_mps: has {dv.shape[0]} rows but dtheta_p_rad has {n}")
    samples = np.zeros(n, dtype=SAMPLE_DTYPE)
    samples["dtheta_p_rad"] = dtheta
    samples["dv_p_mps"] = dv
    if table_angle_rad is not None:
        table = as_float_array("table_angle_rad", table_angle_rad, (), contiguous=False)
        if table.shape[0] != n:
            raise ValueError(f"table_angle_rad: has {table.shape[0]} rows but dtheta_p_rad has {n}")
        samples["table_angle_rad"] = table
    if seq is not None:
        counter = np.asarray(seq)
        if counter.shape != (n,) or not np.issubdtype(counter.dtype, np.integer):
            raise ValueError(f"seq: expected {n} integers, got dtype {counter.dtype} shape {counter.shape}")
        samples["seq"] = counter.astype(np.int64) & 0xFFFFFFFF   # modulo 2^32, as the IMU's counter wraps
    return samples


def check_samples(samples, contiguous=True):
    """``samples`` if it is a 1-D SAMPLE_DTYPE array (C-contiguous unless
    ``contiguous`` is False), else ValueError saying what is wrong."""
    if (type(samples) is np.ndarray and samples.dtype is SAMPLE_DTYPE and samples.ndim == 1
            and samples.flags.c_contiguous):
        return samples          # the common case, checked in a few hundred ns
    if not isinstance(samples, np.ndarray) or samples.dtype != SAMPLE_DTYPE:
        got = samples.dtype if isinstance(samples, np.ndarray) else type(samples).__name__
        raise ValueError(f"samples: expected an array of pyins.native.SAMPLE_DTYPE, got {got} "
                         f"(build one with pyins.native.make_samples)")
    if samples.ndim != 1:
        raise ValueError(f"samples: shape is {samples.shape}, expected (N,)")
    if contiguous and not samples.flags.c_contiguous:
        raise ValueError("samples: array is not C-contiguous (use numpy.ascontiguousarray)")
    return samples


# --- external references ------------------------------------------------------
#: pyins_ref_kind by the names the files and scenarios use.
REF_KINDS = {"gnss_pos": 1, "gnss_vel": 2, "speed_log": 3, "dvl": 4, "zero_velocity": 5}


def check_refs(refs):
    """``refs`` as a 1-D C-contiguous REF_DTYPE array (one record is taken
    as an array of one), else ValueError saying what is wrong. The values
    themselves are the core's to check (pyins_push_ref)."""
    if isinstance(refs, np.void) and refs.dtype == REF_DTYPE:
        refs = np.array([refs], dtype=REF_DTYPE)
    if not isinstance(refs, np.ndarray) or refs.dtype != REF_DTYPE:
        got = refs.dtype if isinstance(refs, np.ndarray) else type(refs).__name__
        raise ValueError(f"refs: expected an array of pyins.contract.REF_DTYPE, got {got} "
                         f"(build one with pyins.contract.make_refs)")
    if refs.ndim != 1:
        raise ValueError(f"refs: shape is {refs.shape}, expected (N,)")
    return np.ascontiguousarray(refs)


def make_refs(kind, tick, value, sigma):
    """A REF_DTYPE array from per-field arrays: kind (N,) ints or one kind
    (a name of REF_KINDS or its number), tick (N,) ints, value and sigma
    (N, 3) float64 in the units of pyins_ref_kind (lat, lon in rad)."""
    tick = np.atleast_1d(np.asarray(tick))
    if tick.ndim != 1 or not np.issubdtype(tick.dtype, np.integer):
        raise ValueError(f"tick: expected integers (N,), got dtype {tick.dtype} shape {tick.shape}")
    n = tick.shape[0]
    if isinstance(kind, str):
        if kind not in REF_KINDS:
            raise ValueError(f"kind: unknown reference kind {kind!r} (known: {', '.join(REF_KINDS)})")
        kind = REF_KINDS[kind]
    refs = np.zeros(n, dtype=REF_DTYPE)
    refs["kind"] = kind
    refs["tick"] = tick
    refs["value"] = as_float_array("value", np.atleast_2d(np.asarray(value, dtype=np.float64)), (3,),
                                   contiguous=False)
    refs["sigma"] = as_float_array("sigma", np.atleast_2d(np.asarray(sigma, dtype=np.float64)), (3,),
                                   contiguous=False)
    return refs
