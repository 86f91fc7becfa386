// math_portable.hpp: sin, cos, sincos, atan2 and asin built only from
// + - * / and sqrt, so that one source gives the same bits on every target.
//
// Why: libm is not reproducible across platforms. glibc (x86-64 host, where
// the Python reference and the tests run) and newlib (Cortex-M target) differ
// by an ulp on some arguments, which is enough to make host and target
// navigation solutions diverge bit-wise. IEEE-754 specifies + - * / and sqrt
// as correctly rounded, so code built only from them is bit-identical
// everywhere the build rules below hold.
//
// Guarantees (error bounds are measured, not proven: tests/c/
// test_math_portable.cpp, millions of points against glibc 2.36, whose
// sin/cos/atan2/asin are correctly rounded or nearly so):
//   sin, cos, sincos  |x| < 1.5 * 2^20 (about 1.57e6): at most 1 ulp from
//                     glibc. sincos(x) gives exactly sin(x) and cos(x);
//                     sin(-x) == -sin(x), cos(-x) == cos(x) bit for bit.
//                     |x| >= 1.5 * 2^20: LOWER ACCURACY. The argument is
//                     reduced in plain double arithmetic, so the result is
//                     the sine/cosine of a point within about half an ulp
//                     of x: absolute error <= ~0.5 ulp(x) (measured), i.e.
//                     ~1.2e-10 at 1.6e6, ~6e-8 at 1e9, ~0.06 at 1e15, and
//                     meaningless above ~2^53 = 9e15. The result is still
//                     finite and in [-1, 1], never UB.
//                     +-Inf or NaN in -> NaN out.
//   atan2             all finite and infinite arguments: at most 1 ulp from
//                     glibc. Signed zeros, infinities and the quadrants follow
//                     C99 Annex F / glibc exactly (e.g. atan2(+0, -0) = +pi,
//                     atan2(-0, +1) = -0, atan2(+Inf, -Inf) = 3 pi / 4).
//                     Any NaN in -> NaN out. Result in [-pi, pi].
//   asin              |x| <= 1: at most 1 ulp from glibc; asin(-x) ==
//                     -asin(x). |x| > 1 or NaN -> NaN.
//   Every NaN returned is the canonical quiet NaN 0x7ff8000000000000 (input
//   NaN payloads are not propagated, so NaN bits match across targets too).
//   No state, no heap, no exceptions, no I/O, no floating-point flags relied on.
//
// Build rules for bit-identity (not for accuracy):
//   * IEEE-754 binary64 double, round-to-nearest-even (the default mode);
//   * every double operation rounded to double (FLT_EVAL_METHOD == 0: no x87
//     extended precision) -- checked at compile time in the .cpp;
//   * no contraction of a*b + c into a fused multiply-add: compile this file
//     with -ffp-contract=off (matters on FMA hardware such as Cortex-M7 FPv5
//     and x86-64 with -mfma); the .cpp also forces it off with a pragma for
//     GCC and Clang. Never -ffast-math or -Ofast.
//
// Method:
//   * Range reduction by pi/2: Cody & Waite (1980), "Software Manual for the
//     Elementary Functions", with pi/2 split into three 33-bit pieces and a
//     53-bit tail (the fdlibm/FreeBSD e_rem_pio2.c constants); the reduced
//     argument is carried as a double-double (hi, lo) into the kernels.
//   * sin/cos kernels on [-pi/4, pi/4], and asin's atan polynomial with the
//     atan(0.5), atan(1), atan(1.5) breakpoints: the minimax coefficients of
//     fdlibm (Sun Microsystems 1993; FreeBSD k_sin.c, k_cos.c, s_atan.c).
//   * asin forms its quotient as a double-double with Dekker's exact
//     product (Dekker 1971, "A floating-point technique for extending the
//     available precision", Numer. Math. 18; Veltkamp splitting) and adds
//     the first-order correction d / (1 + t^2) to atan(t).
//   * atan2 (three per full output record) is table-driven: the octant's
//     ratio r >= 1/64 reduced to the nearest c = i/64, atan(r) = atan(c) +
//     atan(t), t = (y - c x) / (x + c y), |t| <= 1/128; below 1/64 the
//     quotient with its Dekker remainder; the series to t^9; atan(i/64)
//     stored as double-doubles (tools/derive_atan_table.py; Muller,
//     "Elementary Functions", 2016, ch. 6). Two divisions, not four (the
//     cost a call: docs/benchmarks.md). Against glibc it differs by 1 ulp
//     on 0.02-0.5 % of each test set (0.2 % of points aimed at its own
//     edges), never by more.
#pragma once

#include <cmath>

namespace pyins::pmath {

/// Correctly rounded square root. IEEE-754 requires sqrt to be correctly
/// rounded, so this is the one library call allowed here.
inline double sqrt(double x) { return std::sqrt(x); }

/// Sine; see the guarantees above (full accuracy for |x| < 1.5 * 2^20).
double sin(double x);
/// Cosine; see the guarantees above (full accuracy for |x| < 1.5 * 2^20).
double cos(double x);
/// Sine and cosine with one range reduction; *s == sin(x) and *c == cos(x)
/// bit for bit. Both pointers must be valid.
void sincos(double x, double* s, double* c);
/// Angle of (x, y) in [-pi, pi], C99/glibc special cases, <= 1 ulp.
double atan2(double y, double x);
/// Arcsine for |x| <= 1, in [-pi/2, pi/2], <= 1 ulp; NaN outside.
double asin(double x);

}  // namespace pyins::pmath
