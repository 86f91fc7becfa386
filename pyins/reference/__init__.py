"""NumPy reference model of the firmware core, module for module.

Each file mirrors one ``csrc/src`` module with the same function names and
the same order of operations (``earth``, ``attitude``, ``strapdown``,
``coarse_align``, ``fine_align``, ``moving_align``, ``indexing``,
``config``, ``firmware``, ``c_api``); ``abi`` holds the named numbers of
``csrc/include/pyins_core.h``. It is the readable truth the C++ is checked
against; it is per-step and scalar on purpose. ``math_portable`` has no
mirror: NumPy's own sin/cos/atan2 stand in for the core's portable ones.

``Firmware`` (from ``c_api``) is the reference engine: the contract of
``pyins.native.Firmware`` over this mirror, so that a caller chooses
``engine="native"`` or ``"reference"`` and nothing else changes. Nothing
here imports ``pyins.native`` or needs the compiled library: the record
dtypes, errors and sample checks are ``pyins.contract``'s (the ones
``pyins.native`` re-exports), the configuration defaults ``config``'s own
(tests/reference/test_no_library.py runs this package with no library).
"""
from . import (abi, attitude, c_api, coarse_align, config, earth, fine_align, firmware, indexing, kalman,
               moving_align, strapdown)
from .c_api import Firmware

__all__ = ["Firmware", "abi", "attitude", "c_api", "coarse_align", "config", "earth", "fine_align",
           "firmware", "indexing", "kalman", "moving_align", "strapdown"]
