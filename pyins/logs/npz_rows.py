"""An .npz's arrays in rows, in bounded memory: `NpzWriter` writes them
block by block, `iter_npz` reads them back ``block`` rows at a time,
`npz_shape` reads an array's shape from its header."""
import os
import zipfile

import numpy as np

from pyins.logs.files import _Closing, _copy, _read_exact, _remove, _tmp_name
from pyins.logs.options import COMPRESSIONS, DEFAULT_BLOCK


class NpzWriter(_Closing):
    """An .npz written block by block, in bounded memory: `append` sends an
    array's rows to a raw file beside ``path`` as they come, `put` keeps a
    small array whole; `close` assembles the archive (the members np.savez
    writes: ``NAME.npy``, stored, zip64; `numpy.load` reads it as it reads
    np.savez's) under a temporary name and renames it, so a kill at any time
    leaves no file that looks complete. ``compress``: "gzip", "xz" or
    "bzip2" to compress the archive as a whole (a .npz.gz). `abort` removes
    everything written so far. Also a context manager: an exception in the
    block aborts."""

    def __init__(self, path, compress=None):
        self.path, self.compress = os.fspath(path), compress
        self._raw = {}        # name -> [raw path, file, dtype, tail shape, rows]
        self._whole = {}      # name -> array
        self._order = []
        self.closed = False

    def append(self, name, array):
        a = np.ascontiguousarray(array)
        part = self._raw.get(name)
        if part is None:
            tmp = _tmp_name(self.path, f"{name}.part")
            part = self._raw[name] = [tmp, open(tmp, "wb"), a.dtype, a.shape[1:], 0]
            self._order.append(name)
        elif a.dtype != part[2] or a.shape[1:] != part[3]:
            raise ValueError(f"{self.path}: {name}: rows of {a.dtype} {a.shape[1:]} after rows of "
                             f"{part[2]} {part[3]}")
        part[1].write(a.tobytes())
        part[4] += a.shape[0]

    def put(self, name, array):
        if name not in self._whole and name not in self._raw:
            self._order.append(name)
        self._whole[name] = np.asanyarray(array)

    def rows(self, name):
        """Rows appended to ``name`` so far."""
        part = self._raw.get(name)
        return 0 if part is None else part[4]

    def close(self):
        if self.closed:
            return
        for part in self._raw.values():
            part[1].close()
        tmp = _tmp_name(self.path)
        packed = _tmp_name(self.path, "zip") if self.compress else tmp
        try:
            with zipfile.ZipFile(packed, "w", zipfile.ZIP_STORED, allowZip64=True) as zf:
                for name in self._order:
                    with zf.open(f"{name}.npy", "w", force_zip64=True) as f:
                        if name in self._whole:
                            np.lib.format.write_array(f, self._whole[name], allow_pickle=False)
                            continue
                        raw, _, dtype, tail, n = self._raw[name]
                        header = {"descr": np.lib.format.dtype_to_descr(dtype),
                                  "fortran_order": False, "shape": (n,) + tuple(tail)}
                        try:
                            np.lib.format.write_array_header_1_0(f, header)
                        except ValueError:      # a header longer than 64 KiB
                            np.lib.format.write_array_header_2_0(f, header)
                        with open(raw, "rb") as src:
                            _copy(src, f)
            if self.compress:
                opener = next(o for c, _, o in COMPRESSIONS.values() if c == self.compress)
                with open(packed, "rb") as src, opener(tmp, "wb") as dst:
                    _copy(src, dst)
                _remove(packed)
            os.replace(tmp, self.path)
        except BaseException:
            _remove(tmp, packed)
            self.abort()
            raise
        self._discard()
        self.closed = True

    def _discard(self):
        for part in self._raw.values():
            part[1].close()
            _remove(part[0])
        self._raw.clear()

    def abort(self):
        """Remove what was written (the final name is never written before close)."""
        self._discard()
        self.closed = True


def _npz_header(f, path, name):
    version = np.lib.format.read_magic(f)
    if version == (1, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
    else:
        shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
    if fortran or not shape or dtype.hasobject:
        raise ValueError(f"{os.fspath(path)}: {name}: not a C-ordered array of rows")
    return shape, dtype


def npz_shape(path, name):
    """The shape of array ``name`` of an .npz, from its header alone."""
    with zipfile.ZipFile(path) as zf, zf.open(f"{name}.npy") as f:
        return _npz_header(f, path, name)[0]


def iter_npz(path, name, block=DEFAULT_BLOCK):
    """The rows of array ``name`` of an .npz, ``block`` rows at a time,
    without reading the whole array (members stored as np.savez and
    `NpzWriter` write them; a compressed member is decompressed as it is
    read): e.g. a 72 h replay's navigation.npz (112 MB of records) decimated
    in bounded memory. Yields read-only arrays."""
    with zipfile.ZipFile(path) as zf, zf.open(f"{name}.npy") as f:
        shape, dtype = _npz_header(f, path, name)
        row = dtype.itemsize * int(np.prod(shape[1:], dtype=np.int64))
        for start in range(0, shape[0], block):
            m = min(block, shape[0] - start)
            raw = _read_exact(f, m * row, None, os.fspath(path))
            if len(raw) != m * row:
                raise ValueError(f"{os.fspath(path)}: {name}: the member ends at row {start + len(raw) // row} "
                                 f"of {shape[0]}")
            yield np.frombuffer(raw, dtype).reshape((m,) + tuple(shape[1:]))
