"""Angles wrapped to one turn, for the firmware mirror (and the plant's).

Mirrors ``csrc/src/angle.hpp``: the one scalar ``wrap_two_pi`` and
``wrap_pi`` of the mirror, the same operations in the same order. The plant
(``csrc/plant/plant.cpp``) wraps its encoder reading with the same C++
function.
"""
import math

import numpy as np

from pyins.units import TWO_PI


def wrap_two_pi(a):
    """Angle in [0, 2 pi) for any finite input (mirrors wrap_two_pi: a
    rounding to 2 pi or below 0, or a too large to wrap, gives 0)."""
    if 0.0 <= a < TWO_PI:
        return a
    w = a - TWO_PI * math.floor(a / TWO_PI)
    if not (0.0 <= w < TWO_PI):
        w = 0.0
    return w


def wrap_pi(a):
    """Angle in (-pi, pi] for an input within (-3 pi, 3 pi] (mirrors wrap_pi)."""
    if a > np.pi:
        return a - TWO_PI
    if a <= -np.pi:
        return a + TWO_PI
    return a
