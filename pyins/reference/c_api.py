"""The C ABI over the mirror's firmware instance, and the reference engine.

Mirrors ``csrc/src/c_api.cpp``: ``pyins_init`` (check everything, then
build the instance), ``pyins_step``, ``pyins_run`` (stop at the first
rejected sample), ``pyins_run_decimated`` (one record each time the tick
reaches a multiple of ``every``), ``pyins_run_nav`` (the same with the
compact record), ``pyins_get_output``, ``pyins_get_nav`` and
``pyins_index_reset``, over :class:`pyins.reference.firmware.Firmware`.

:class:`Firmware` is the reference engine: the contract of
``pyins.native.Firmware`` (the same constructor, ``step``, ``run``,
``run_nav``, ``nav``, ``output``, ``index_reset``, ``snapshot``/``restore``, ``last_status`` and
``config``), the same exceptions (``contract.ConfigError``,
``contract.SampleError``, ``contract.SnapshotError``, ``contract.CoreError``,
which ``pyins.native`` re-exports) and records of ``contract.OUTPUT_DTYPE``,
so that a caller swaps ``engine="native"|"reference"`` without another line.
The configuration is the mirror's own defaults (``config.config_default``)
with the caller's fields written over them by ``contract.set_config_fields``
(the C struct's names, shapes and types, the checks ``native.make_config``
applies), then handed to the mirror as a dict: nothing here loads the
compiled library, and a drift of the defaults between the twins shows
(tests/native/test_contract.py).

Records of the two engines agree in every integer field and to a few ulps
in the floats (portable vs libm sin/cos, Eigen vs NumPy summation order),
not bit for bit; each engine alone is deterministic, so a run through one
engine reproduces its own records bit for bit (tests/crosscheck/test_engines.py).

A snapshot of this engine is its own: a blob of the reference state (not
the C instance's bytes), restored only by this engine.
"""
import hashlib
import io
import pickle

import numpy as np

from .. import contract
from . import abi, config, firmware
from .config import config_default

#: The header of a reference snapshot: magic, then the SHA-256 of the payload.
SNAP_MAGIC = b"PYRS\x01\x00\x00\x00"
_SNAP_HEADER = len(SNAP_MAGIC) + 32


def config_from_struct(cfg):
    """A ``pyins_config`` (cffi, of either engine's FFI) as the mirror's
    configuration dict."""
    out = {}
    for name in contract.CONFIG_FIELDS:
        value = getattr(cfg, name)
        if name == "index_steps":
            value = [(s.stop_ticks, s.kind, s.angle_rad) for s in value]
        elif isinstance(value, contract.ffi.CData):
            value = np.array(list(value), dtype=np.float64)
        out[name] = value
    return out


def struct_from_config(cfg):
    """The mirror's configuration dict as a ``pyins_config *`` (of the
    contract's FFI; fields the dict lacks stay 0)."""
    struct = contract.ffi.new("pyins_config *")
    return contract.set_config_fields(struct, cfg)


def make_config(config=None, **fields):   # the parameter shadows the module here, as in native
    """The reference twin of ``native.make_config``: a ``pyins_config *``
    (contract's FFI) holding the mirror's defaults (``config.config_default``)
    and the caller's fields over them, with the same checks and messages
    (unknown key, shape, type; ``vertical_mode`` 'hold' / 'free')."""
    merged = dict(config or {})
    merged.update(fields)
    return contract.set_config_fields(struct_from_config(config_default()), merged)


def pyins_status_str(status):
    """Mirrors pyins_status_str (c_api.cpp): the contract's text."""
    return contract.status_str(status)


def pyins_config_check(cfg):
    """Mirrors pyins_config_check: PYINS_OK or the first PYINS_E_CONFIG_*
    of a ``pyins_config *`` (either engine's FFI)."""
    return config.config_check(config_from_struct(cfg))


def pyins_init(raw):
    """(status, instance or None): check the whole configuration, then build."""
    status = config.config_check(raw)
    if status != abi.PYINS_OK:
        return status, None
    return abi.PYINS_OK, firmware.Firmware(raw)


def fill(record, out):
    """Write one output dict into a ``pyins_output`` record (padding stays 0)."""
    for name, value in out.items():
        record[name] = value


def pyins_step(fw, dtheta_p, dv_p, table_angle_rad, seq, record):
    """One sample; the record always holds the state after the call."""
    status, out = fw.step(dtheta_p, dv_p, table_angle_rad, seq)
    fill(record, out)
    return status


def pyins_run(fw, samples, outputs):
    """(status, n_done): step through the samples, stop at a rejected one."""
    for i in range(samples.shape[0]):
        s = samples[i]
        status = pyins_step(fw, s["dtheta_p_rad"], s["dv_p_mps"], float(s["table_angle_rad"]),
                            int(s["seq"]), outputs[i])
        if status < 0:   # rejected; PYINS_W_* notices go on (the records carry them)
            return status, i
    return abi.PYINS_OK, samples.shape[0]


def pyins_run_decimated(fw, samples, every, record=None):
    """(status, n_done, records): a record each time the tick reaches (or a
    bridged gap passes) the next multiple of ``every``; ``record`` writes it
    (the firmware's output, or nav_record for pyins_run_nav)."""
    record = fw.output if record is None else record
    if every < 1:
        return abi.PYINS_E_BAD_ARG, 0, []
    records = []
    nxt = (fw.tick // every + 1) * every   # the next multiple of every after the current tick
    for i in range(samples.shape[0]):
        s = samples[i]
        status, _ = fw.step(s["dtheta_p_rad"], s["dv_p_mps"], float(s["table_angle_rad"]), int(s["seq"]))
        if status < 0:
            return status, i, records
        if fw.tick >= nxt:
            nxt = (fw.tick // every + 1) * every
            records.append(record())
    return abi.PYINS_OK, samples.shape[0], records


def pyins_run_nav(fw, samples, every):
    """pyins_run_decimated with the compact record."""
    return pyins_run_decimated(fw, samples, every, record=fw.nav_record)


def pyins_get_output(fw, record):
    fill(record, fw.output())
    return abi.PYINS_OK


def pyins_get_nav(fw, record):
    fill(record, fw.nav_record())
    return abi.PYINS_OK


def pyins_index_reset(fw):
    fw.index_reset()
    return abi.PYINS_OK


def pyins_push_ref(fw, ref):
    """One REF_DTYPE record (mirrors pyins_push_ref)."""
    return fw.push_ref(int(ref["kind"]), int(ref["tick"]), ref["value"], ref["sigma"], int(ref["reserved"]))


def _records(status, n_done, records, dtype):
    """The record dicts of a decimated run as an array of ``dtype``;
    SampleError (carrying them) when the run stopped at a rejected sample."""
    out = np.zeros(len(records), dtype=dtype)
    for rec, o in zip(out, records):
        fill(rec, o)
    if status != abi.PYINS_OK:
        raise contract.SampleError(status, n_done, out)
    return out


class _StateUnpickler(pickle.Unpickler):
    """Rebuilds the mirror's own classes and NumPy arrays, nothing else."""

    def find_class(self, module, name):
        if module.startswith(("pyins.reference.", "numpy")) or (module, name) in (
                ("builtins", "complex"), ("builtins", "slice"), ("builtins", "range")):
            return super().find_class(module, name)
        raise pickle.UnpicklingError(f"{module}.{name}")


class Firmware:
    """The reference engine, with the contract of ``pyins.native.Firmware``.

    >>> fw = Firmware(lat_rad=0.5, euler_b_rad=[0, 0, 1.0])
    >>> rec = fw.step([0, 0, 0], [0, 0, 0.098])        # one OUTPUT_DTYPE record
    >>> out = fw.run(contract.make_samples(dtheta, dv))   # doctest: +SKIP
    """

    def __init__(self, config=None, **fields):
        cfg = make_config(config, **fields)
        status, fw = pyins_init(config_from_struct(cfg))
        if status != abi.PYINS_OK:
            raise contract.ConfigError(status, "pyins_init")
        self._fw = fw
        self.last_status = abi.PYINS_OK
        self.config = contract.scalar_config(cfg)

    @property
    def instance(self):
        """The mirror's firmware instance (``pyins.reference.firmware.Firmware``)."""
        return self._fw

    def output(self):
        """The current state as one OUTPUT_DTYPE record."""
        out = np.zeros(1, dtype=contract.OUTPUT_DTYPE)
        pyins_get_output(self._fw, out[0])
        return out[0].copy()

    def step(self, dtheta_p_rad, dv_p_mps, table_angle_rad=0.0, seq=0):
        """One tick; returns its OUTPUT_DTYPE record. SampleError if rejected;
        a PYINS_W_* notice is kept in ``last_status``."""
        dtheta = _vector3("dtheta_p_rad", dtheta_p_rad)
        dv = _vector3("dv_p_mps", dv_p_mps)
        out = np.zeros(1, dtype=contract.OUTPUT_DTYPE)
        status = pyins_step(self._fw, dtheta, dv, float(table_angle_rad), int(seq) & 0xFFFFFFFF, out[0])
        self.last_status = status
        if status < 0:
            raise contract.SampleError(status, 0, np.zeros(0, dtype=contract.OUTPUT_DTYPE))
        return out[0].copy()

    def run(self, samples, outputs=None, every=1):
        """Step through a SAMPLE_DTYPE array (see ``pyins.native.Firmware.run``):
        one record per sample, or with ``every=k`` one record after each
        step whose tick is a multiple of k; SampleError at the first
        rejected sample, carrying the records before it."""
        samples = _check_samples(samples)
        n = samples.shape[0]
        if every != 1:
            every = int(every)
            if every < 1:
                raise ValueError(f"every: must be a positive number of ticks, got {every}")
            return _records(*pyins_run_decimated(self._fw, samples, every), contract.OUTPUT_DTYPE)
        if outputs is None:
            outputs = np.zeros(n, dtype=contract.OUTPUT_DTYPE)
        elif (not isinstance(outputs, np.ndarray) or outputs.dtype != contract.OUTPUT_DTYPE
              or outputs.shape != (n,) or not outputs.flags.c_contiguous
              or not outputs.flags.writeable):
            raise ValueError("outputs: expected a writeable C-contiguous OUTPUT_DTYPE array "
                             f"of shape ({n},)")
        status, n_done = pyins_run(self._fw, samples, outputs)
        if status != abi.PYINS_OK:
            raise contract.SampleError(status, n_done, outputs[:n_done].copy())
        return outputs

    def run_nav(self, samples, every=1):
        """As ``run`` with the compact record (see ``native.Firmware.run_nav``)."""
        samples = _check_samples(samples)
        every = int(every)
        if every < 1:
            raise ValueError(f"every: must be a positive number of ticks, got {every}")
        return _records(*pyins_run_nav(self._fw, samples, every), contract.NAV_DTYPE)

    def nav(self):
        """The current state as one NAV_DTYPE record."""
        out = np.zeros(1, dtype=contract.NAV_DTYPE)
        pyins_get_nav(self._fw, out[0])
        return out[0].copy()

    def index_reset(self):
        """Leave the indexing FAULT state (pyins_index_reset)."""
        pyins_index_reset(self._fw)

    def push_ref(self, refs):
        """External references, in order (see ``native.Firmware.push_ref``)."""
        refs = contract.check_refs(refs)
        for i in range(refs.shape[0]):
            status = pyins_push_ref(self._fw, refs[i])
            if status != abi.PYINS_OK:
                raise contract.RefError(status, i)

    def snapshot(self):
        """The whole reference state as a checksummed blob (bytes)."""
        payload = pickle.dumps((self._fw, self.last_status, self.config), protocol=4)
        return SNAP_MAGIC + hashlib.sha256(payload).digest() + payload

    def restore(self, blob):
        """Replace the state with a snapshot of this engine; a truncated,
        corrupted or foreign blob raises SnapshotError and changes nothing."""
        if not isinstance(blob, (bytes, bytearray, memoryview)):
            raise ValueError(f"snapshot: expected bytes, got {type(blob).__name__}")
        blob = bytes(blob)
        if len(blob) < _SNAP_HEADER:
            raise contract.SnapshotError(abi.PYINS_E_SNAPSHOT_SIZE, "pyins_restore")
        if blob[:len(SNAP_MAGIC)] != SNAP_MAGIC:
            status = (abi.PYINS_E_SNAPSHOT_VERSION if blob[:4] == SNAP_MAGIC[:4]
                      else abi.PYINS_E_SNAPSHOT_CORRUPT)
            raise contract.SnapshotError(status, "pyins_restore")
        payload = blob[_SNAP_HEADER:]
        if hashlib.sha256(payload).digest() != blob[len(SNAP_MAGIC):_SNAP_HEADER]:
            raise contract.SnapshotError(abi.PYINS_E_SNAPSHOT_CORRUPT, "pyins_restore")
        try:
            fw, last_status, cfg = _StateUnpickler(io.BytesIO(payload)).load()
        except (pickle.UnpicklingError, ValueError, TypeError, EOFError) as exc:
            raise contract.SnapshotError(abi.PYINS_E_SNAPSHOT_CORRUPT, f"pyins_restore ({exc})") from None
        self._fw, self.last_status, self.config = fw, last_status, cfg

    @classmethod
    def from_snapshot(cls, blob):
        """A new instance holding a snapshot's state."""
        fw = cls.__new__(cls)
        fw.restore(blob)
        return fw


def _vector3(name, value):
    a = np.asarray(value, dtype=np.float64)
    if a.shape != (3,):
        raise ValueError(f"{name}: shape is {a.shape}, expected (3,)")
    return a


def _check_samples(samples):
    # the contract's check; this engine reads rows, so views need not be contiguous
    return contract.check_samples(samples, contiguous=False)
