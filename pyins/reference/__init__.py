"""NumPy reference model of the firmware core, module for module.

Each file mirrors one ``csrc/src`` module with the same function names and
the same order of operations (``earth``, ``attitude``, ``strapdown``,
``coarse_align``, ``firmware``). It is the readable truth the C++ is checked against; it is
per-step and scalar on purpose. ``math_portable`` and ``c_api`` have no
mirror: NumPy's own sin/cos/atan2 stand in for the core's portable ones, and
the C ABI is Python's ``pyins.native``.
"""
from . import attitude, coarse_align, earth, fine_align, firmware, kalman, strapdown

__all__ = ["attitude", "coarse_align", "earth", "fine_align", "firmware", "kalman", "strapdown"]
