#!/usr/bin/env python3
"""Derive the weight functions of the moving-base coarse alignment (FIT).

The position integral of the velocity integral on a moored ship is
    P^ib0(t) = C_i^ib0 P^i(t) + b t + c + d(t)
with an unknown initial velocity b, an unknown offset c and a bounded wave
displacement d(t) (csrc/src/coarse_align.hpp). FIT weights the grid by two
functions phi(s) of s = t / T that

- are orthogonal to 1 and s on [0, 1] (b and c drop out),
- vanish with their first derivative at s = 0 and s = 1 (phi = s^2 (1-s)^2
  q(s): a wave's leakage through the ends falls as (w T)^-3),
- phi_a also orthogonal to s^3 and normalised to int phi_a s^2 = 1 (it
  reads the t^2 term: gravity), phi_b orthogonal to s^2 and normalised to
  int phi_b s^3 = 1 (it reads the t^3 term: the Earth's rotation).

With q cubic each is unique. This script solves the linear conditions with
exact rational arithmetic (fractions; no dependency) and prints q's
coefficients, lowest power first: the integers written in coarse_align.cpp
and pyins/reference/coarse_align.py (expect q_a = [45360, -350280, 766080,
-498960], q_b = [-27720, 221760, -498960, 332640]).
"""
from fractions import Fraction


def poly_mul(a, b):
    out = [Fraction(0)] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            out[i + j] += x * y
    return out


def moment(p, n):
    """int_0^1 p(s) s^n ds for coefficients p (lowest power first)."""
    return sum(c * Fraction(1, i + n + 1) for i, c in enumerate(p))


def solve(rows, rhs):
    """Gauss-Jordan elimination over the rationals."""
    n = len(rows)
    m = [list(r) + [b] for r, b in zip(rows, rhs)]
    for col in range(n):
        piv = next(r for r in range(col, n) if m[r][col] != 0)
        m[col], m[piv] = m[piv], m[col]
        m[col] = [v / m[col][col] for v in m[col]]
        for r in range(n):
            if r != col and m[r][col] != 0:
                f = m[r][col]
                m[r] = [a - f * b for a, b in zip(m[r], m[col])]
    return [m[r][n] for r in range(n)]


def weight(zero_moments, unit_moment):
    """q (cubic) such that phi = s^2 (1-s)^2 q has the given zero moments
    and int phi s^unit_moment = 1."""
    w = poly_mul(poly_mul([0, 0, 1], [1, -1]), [1, -1])     # s^2 (1 - s)^2
    basis = [poly_mul(w, [0] * j + [1]) for j in range(4)]
    rows = [[moment(b, n) for b in basis] for n in zero_moments + [unit_moment]]
    return solve(rows, [Fraction(0)] * len(zero_moments) + [Fraction(1)])


def weights():
    return weight([0, 1, 3], 2), weight([0, 1, 2], 3)


def main():
    qa, qb = weights()
    print("q_a =", [str(c) for c in qa])
    print("q_b =", [str(c) for c in qb])


if __name__ == "__main__":
    main()
