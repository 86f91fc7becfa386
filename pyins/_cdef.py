"""Read the cffi declaration block out of the core's public C headers.

The block between ``/* CDEF-BEGIN */`` and ``/* CDEF-END */`` of each header
is passed to ``cffi.FFI.cdef`` verbatim, so the binding and the C ABI cannot
drift apart: there is one source of truth.
"""
import re

_BLOCK = re.compile(r"/\* CDEF-BEGIN \*/(.*?)/\* CDEF-END \*/", re.S)


def read_cdef(text):
    """The declaration block of a header's text; ValueError if it has none."""
    m = _BLOCK.search(text)
    if m is None:
        raise ValueError("header has no CDEF-BEGIN/CDEF-END block")
    return m.group(1)
