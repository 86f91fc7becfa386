"""Exact time for the simulator: node times as (hi, lo) pairs and phases
reduced to a fraction of a cycle without losing bits.

A time is an exact sum ``t + t_lo`` of two floats. `split_times` builds the
Gauss-Legendre node times of ticks as such pairs, and `frac_cycles` reduces
``freq * (t + t_lo)`` to a fraction of a cycle with an error-free product, so
a 24-h or 72-h run keeps sinusoid phases exact to ~1e-16 rad instead of
ulp(2 pi f t) ~ 1e-11 rad. Every motion profile (`pyins.sim.motion`,
`pyins.sim.ship`, `pyins.sim.turntable`) takes its times through `as_times`.

1. Error-free transformations: `two_prod`, `two_sum`.
2. Tick times as exact pairs: `split_times`.
3. Phases: `frac_cycles`.
4. The times a profile is asked for: `as_times`.

Everything is element-wise in NumPy and needs no FMA.

References
----------
- Dekker (1971), "A floating-point technique for extending the available
  precision", Numer. Math. 18: the splitting, the two-product and two-sum.
"""
import numpy as np

_SPLITTER = 134217729.0  # 2**27 + 1


# ---------------------------------------------------------------------------
# 1. Error-free transformations (Dekker 1971)
# ---------------------------------------------------------------------------
def _split(a):
    c = _SPLITTER * a
    hi = c - (c - a)
    return hi, a - hi


def two_prod(a, b):
    """``a * b == p + e`` exactly (Dekker's product; inputs well below 1e300)."""
    p = a * b
    a_hi, a_lo = _split(a)
    b_hi, b_lo = _split(b)
    e = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo
    return p, e


def two_sum(a, b):
    """``a + b == s + e`` exactly (Knuth's two-sum)."""
    s = a + b
    bb = s - a
    e = (a - (s - bb)) + (b - bb)
    return s, e


# ---------------------------------------------------------------------------
# 2. Tick times
# ---------------------------------------------------------------------------
def split_times(ticks, dt, t0=0.0, frac=0.0):
    """Times ``t0 + (ticks + frac) * dt`` as an exact pair ``(t_hi, t_lo)``.

    Parameters
    ----------
    ticks : array_like of int
        Tick indices (exact in float64 below 2**53).
    dt : float
        Tick length [s].
    t0 : float
        Time of tick 0 [s].
    frac : array_like
        Fraction of a tick in [0, 1], broadcast against ``ticks``.

    Returns
    -------
    t_hi, t_lo : ndarray
        ``t_hi + t_lo`` equals the time to ~1e-27 s; ``t_lo`` may be as large
        as one tick (it carries the in-tick offset).
    """
    g = np.asarray(ticks, dtype=float)
    p, e1 = two_prod(g, dt)
    t_hi, e2 = two_sum(np.full_like(p, t0), p)
    t_lo = (e1 + e2) + np.asarray(frac, dtype=float) * dt
    t_hi, t_lo = np.broadcast_arrays(t_hi, t_lo)
    return np.array(t_hi), np.array(t_lo)


# ---------------------------------------------------------------------------
# 3. Phases
# ---------------------------------------------------------------------------
def frac_cycles(freq, t, t_lo=None):
    """``freq * (t + t_lo)`` reduced to a fraction of a cycle, about [-0.5, 0.5].

    The product ``freq * t`` is formed exactly (two-product), its integer part
    removed exactly, and the low-order parts added afterwards, so the result is
    accurate to ~1e-16 cycles whatever the size of ``t``.
    """
    p, e = two_prod(freq, t)
    n = np.rint(p)
    c = (p - n) + e
    if t_lo is not None:
        c = c + freq * t_lo
    return c


# ---------------------------------------------------------------------------
# 4. The times a profile is asked for
# ---------------------------------------------------------------------------
def as_times(t, t_lo):
    """``(t, t_lo)`` as a 1-D float array and None or an array of its shape.

    ``t_lo`` is the optional low-order part (the time meant is ``t + t_lo``);
    callers that have none pass None. ValueError if ``t`` is not 1-D.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if t.ndim != 1:
        raise ValueError(f"times must be a 1-D array, got shape {t.shape}")
    if t_lo is None:
        return t, None
    t_lo = np.broadcast_to(np.asarray(t_lo, dtype=float), t.shape)
    return t, t_lo
