#!/usr/bin/env python3
"""Derive the three-sample coning and sculling coefficients of strapdown.hpp.

Assume the angular rate omega(t) and specific force f(t) are quadratic in
time over the last three ticks [-2T, T]. The exact coning term of the
current tick, (1/2) int_0^T alpha x omega dt, and sculling term,
(1/2) int_0^T (alpha x f - omega x v) dt (Savage 1998, Parts 1 and 2), are
then bilinear in the three ticks' increments; this script solves for the
coefficients with sympy and prints them (expect 121/720, -31/720, 1/720;
with a linear rate over two ticks the same procedure gives the textbook
1/12). Needs sympy: pip install sympy.
"""
import sympy as sp


def main():
    t, T = sp.symbols("t T", positive=True)

    def vec(name):
        return sp.Matrix(sp.symbols(f"{name}x {name}y {name}z"))

    a, b, c, d, e, f = (vec(n) for n in "abcdef")
    omega = a + b * t + c * t**2
    force = d + e * t + f * t**2

    def integ(v, lo, hi):
        return v.applyfunc(lambda x: sp.integrate(x, (t, lo, hi)))

    th = [integ(omega, -2 * T, -T), integ(omega, -T, 0), integ(omega, 0, T)]
    dv = [integ(force, -2 * T, -T), integ(force, -T, 0), integ(force, 0, T)]
    alpha = integ(omega, 0, t)
    vel = integ(force, 0, t)
    cone = (alpha.cross(omega) / 2).applyfunc(lambda x: sp.integrate(x, (t, 0, T)))
    scul = ((alpha.cross(force) - omega.cross(vel)) / 2).applyfunc(
        lambda x: sp.integrate(x, (t, 0, T)))

    k1, k2, k3 = sp.symbols("k_near k_far k_past")
    model = k1 * th[1].cross(th[2]) + k2 * th[0].cross(th[2]) + k3 * th[0].cross(th[1])
    eqs = sp.Poly(sp.expand(model[0] - cone[0]), *a, *b, *c).coeffs()
    print("coning :", sp.solve(eqs, [k1, k2, k3]))
    model = (k1 * (th[1].cross(dv[2]) + dv[1].cross(th[2]))
             + k2 * (th[0].cross(dv[2]) + dv[0].cross(th[2]))
             + k3 * (th[0].cross(dv[1]) + dv[0].cross(th[1])))
    eqs = sp.Poly(sp.expand(model[0] - scul[0]), *a, *b, *c, *d, *e, *f).coeffs()
    print("sculling:", sp.solve(eqs, [k1, k2, k3]))


if __name__ == "__main__":
    main()
