// math_portable.cpp: portable sin, cos, sincos, atan2, asin.
//
// See math_portable.hpp for the guarantees, the build rules and the
// references. Only + - * /, comparisons, sqrt and integer bit operations are
// used; no libm function is called.
#include "math_portable.hpp"

#include <cfloat>
#include <cstdint>
#include <cstring>
#include <limits>

#include "units.hpp"

static_assert(std::numeric_limits<double>::is_iec559,
              "pmath needs IEEE-754 binary64 double");
#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#error "pmath needs FLT_EVAL_METHOD == 0 (each double operation rounded to double)"
#endif

// Fused multiply-add contraction changes the bits (and breaks the exact
// TwoSum/TwoProduct steps), so forbid it here even if the build forgets
// -ffp-contract=off.
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

namespace pyins::pmath {
namespace {

// ---------------------------------------------------------------------------
// Bit-level helpers (integer operations only).
// ---------------------------------------------------------------------------

constexpr double kInf = std::numeric_limits<double>::infinity();
/// The one NaN returned (bits 0x7ff8000000000000 on every target).
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::uint64_t bits_of(double x) {
    std::uint64_t u;
    std::memcpy(&u, &x, sizeof u);
    return u;
}

double from_bits(std::uint64_t u) {
    double x;
    std::memcpy(&x, &u, sizeof x);
    return x;
}

bool sign_bit(double x) { return (bits_of(x) >> 63) != 0; }

/// |x| by clearing the sign bit (also correct for -0 and NaN).
double magnitude(double x) {
    return from_bits(bits_of(x) & ~(std::uint64_t{1} << 63));
}

bool is_nan(double x) { return x != x; }

bool is_finite(double x) { return magnitude(x) <= DBL_MAX; }  // false for NaN

// ---------------------------------------------------------------------------
// Error-free transformations. A double-double value is hi + lo, unevaluated.
// ---------------------------------------------------------------------------

struct DD {
    double hi;
    double lo;
};

/// Knuth's TwoSum: hi = fl(a + b) and hi + lo == a + b exactly. No condition
/// on the magnitudes of a and b (barring overflow).
DD two_sum(double a, double b) {
    const double s = a + b;
    const double b_part = s - a;
    const double a_part = s - b_part;
    const double err = (a - a_part) + (b - b_part);
    return {s, err};
}

/// Veltkamp splitting: a == hi + lo exactly, both with at most 26 significant
/// bits, so products of the pieces are exact. Needs |a| < 2^996.
DD split(double a) {
    constexpr double kSplitter = 134217729.0;  // 2^27 + 1
    const double c = kSplitter * a;
    const double hi = c - (c - a);
    return {hi, a - hi};
}

/// Dekker's exact product: hi = fl(a * b) and hi + lo == a * b exactly, when
/// |a|, |b| < 2^996, a * b does not overflow, and e(a) + e(b) >= -969
/// (so that the error term is not lost to underflow).
DD two_prod(double a, double b) {
    const double p = a * b;
    const DD as = split(a);
    const DD bs = split(b);
    const double err =
        ((as.hi * bs.hi - p) + as.hi * bs.lo + as.lo * bs.hi) + as.lo * bs.lo;
    return {p, err};
}

// ---------------------------------------------------------------------------
// Constants. Values are hex literals (exact); comments give the decimal.
// ---------------------------------------------------------------------------

// pi/2 = kPio2_1 + kPio2_2 + kPio2_3 + kPio2_3t + (error < 1e-48). The first
// three have 33 significant bits, so fn * kPio2_k is exact for |fn| < 2^20.
// (fdlibm e_rem_pio2.c: pio2_1, pio2_2, pio2_3, pio2_3t.)
constexpr double kPio2_1 = 0x1.921fb544p+0;          // 1.57079632673412561417e+00
constexpr double kPio2_2 = 0x1.0b4611a6p-34;         // 6.07710050630396597660e-11
constexpr double kPio2_3 = 0x1.3198a2ep-69;          // 2.02226624871116645580e-21
constexpr double kPio2_3t = 0x1.b839a252049c1p-104;  // 8.47842766036889956997e-32
// pi/2 - kPio2_1 rounded to double (fdlibm pio2_1t); large-argument steps only.
constexpr double kPio2_1t = 0x1.0b4611a626331p-34;   // 6.07710050650619224932e-11
constexpr double kInvPio2 = 0x1.45f306dc9c883p-1;    // 2/pi, 6.36619772367581382433e-01

// Correctly rounded multiples of pi, and the rounding error of pi (kPi is
// units.hpp's, the double nearest pi).
static_assert(kPi == 0x1.921fb54442d18p+1, "kPi: 3.14159265358979311600e+00");
constexpr double kPiLo = 0x1.1a62633145c07p-53;  // pi - kPi = 1.22464679914735317723e-16
constexpr double kPio2 = 0x1.921fb54442d18p+0;   // 1.57079632679489655800e+00
constexpr double kPio4 = 0x1.921fb54442d18p-1;   // 7.85398163397448278999e-01
constexpr double k3Pio4 = 0x1.2d97c7f3321d2p+1;  // 2.35619449019234483700e+00

// Arguments with |x| below this take the accurate (medium) reduction: then
// |x * 2/pi| < 0.955 * 2^20, so fn < 2^20 and the products fn * kPio2_k exact.
constexpr double kMediumLimit = 0x1.8p+20;  // 1572864

// ---------------------------------------------------------------------------
// Range reduction for sin and cos.
// ---------------------------------------------------------------------------

/// x == quadrant * pi/2 + (hi + lo)  (mod 2 pi), with |hi + lo| <= ~pi/4.
struct Reduced {
    unsigned quadrant;  // 0..3
    double hi;
    double lo;
};

/// An integer within 1/2 (+ 1 ulp) of t, as a double; t finite. Rounds half
/// away from zero, symmetric in sign. An off-by-one next to a half-integer
/// only makes the reduced argument land a hair outside pi/4, which the
/// kernels tolerate.
double nearest_integer(double t) {
    if (!(magnitude(t) < 0x1p52)) {
        return t;  // every double this large is an integer
    }
    const double biased = t < 0.0 ? t - 0.5 : t + 0.5;
    return static_cast<double>(static_cast<std::int64_t>(biased));  // truncates
}

/// fn mod 4 for an integer-valued double fn (two's-complement wrap of a
/// negative fn gives the right residue).
unsigned quadrant_of(double fn) {
    if (!(magnitude(fn) < 0x1p62)) {
        return 0u;  // |fn| >= 2^62 is a multiple of 4
    }
    const auto n = static_cast<std::uint64_t>(static_cast<std::int64_t>(fn));
    return static_cast<unsigned>(n & 3u);
}

/// Cody-Waite reduction of a finite x.
Reduced reduce(double x) {
    if (magnitude(x) <= kPio4) {
        return {0u, x, 0.0};
    }
    unsigned quadrant = 0u;

    // Large arguments (lower accuracy, see the header). fn * kPio2_1 is no
    // longer exact, so each step moves the argument by up to about half an ulp
    // of the current x; the step leaves |x| <~ pi/4 + |x| * 2^-51, so about 20
    // steps (19 measured for DBL_MAX) bring any finite double below
    // kMediumLimit. The cap of 40 only bounds the loop.
    for (int step = 0; step < 40 && !(magnitude(x) < kMediumLimit); ++step) {
        const double fn = nearest_integer(x * kInvPio2);
        quadrant += quadrant_of(fn);
        x = (x - fn * kPio2_1) - fn * kPio2_1t;
    }
    if (!(magnitude(x) < kMediumLimit)) {
        x = 0.0;  // unreachable for finite x; keeps the int conversion defined
    }

    // Medium arguments: x - fn * pi/2 to ~150 bits. |fn| < 2^20, so the
    // three products fn * kPio2_k are exact; x - fn * kPio2_1 is exact by
    // Sterbenz's lemma (the two are within a factor 2); the two TwoSums are
    // exact; only the tail terms (below 2^-80 relative) are rounded.
    const double fn = nearest_integer(x * kInvPio2);
    quadrant += quadrant_of(fn);
    const double r1 = x - fn * kPio2_1;
    const DD r2 = two_sum(r1, -(fn * kPio2_2));
    const DD r3 = two_sum(r2.hi, -(fn * kPio2_3));
    const double tail = (r2.lo + r3.lo) - fn * kPio2_3t;
    const DD r = two_sum(r3.hi, tail);
    return {quadrant & 3u, r.hi, r.lo};
}

// ---------------------------------------------------------------------------
// Kernels on [-pi/4, pi/4]; the argument is x + y with |y| <= ulp(x)/2.
// fdlibm coefficients; |error of the polynomial| < 2^-58 (FreeBSD k_sin.c,
// k_cos.c).
// ---------------------------------------------------------------------------

/// sin(x + y) ~ x + S1 x^3 + ... + S6 x^13, with the first-order y terms.
double kernel_sin(double x, double y) {
    constexpr double S1 = -0x1.5555555555549p-3;   // -1.66666666666666324348e-01
    constexpr double S2 = 0x1.111111110f8a6p-7;    //  8.33333333332248946124e-03
    constexpr double S3 = -0x1.a01a019c161d5p-13;  // -1.98412698298579493134e-04
    constexpr double S4 = 0x1.71de357b1fe7dp-19;   //  2.75573137070700676789e-06
    constexpr double S5 = -0x1.ae5e68a2b9cebp-26;  // -2.50507602534068634195e-08
    constexpr double S6 = 0x1.5d93a5acfd57cp-33;   //  1.58969099521155010221e-10
    const double z = x * x;
    const double w = z * z;
    const double r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    const double v = z * x;
    // x + v*S1 + v*z*r, plus y * (1 - z/2) as the correction for y.
    return x - ((z * (0.5 * y - v * r) - y) - v * S1);
}

/// cos(x + y) ~ 1 - x^2/2 + C1 x^4 + ... + C6 x^14, with the first-order y
/// term; 1 - x^2/2 is formed so that its rounding error is recovered.
double kernel_cos(double x, double y) {
    constexpr double C1 = 0x1.555555555554cp-5;    //  4.16666666666666019037e-02
    constexpr double C2 = -0x1.6c16c16c15177p-10;  // -1.38888888888741095749e-03
    constexpr double C3 = 0x1.a01a019cb1590p-16;   //  2.48015872894767294178e-05
    constexpr double C4 = -0x1.27e4f809c52adp-22;  // -2.75573143513906633035e-07
    constexpr double C5 = 0x1.1ee9ebdb4b1c4p-29;   //  2.08757232129817482790e-09
    constexpr double C6 = -0x1.8fae9be8838d4p-37;  // -1.13596475577881948265e-11
    const double z = x * x;
    const double w = z * z;
    const double r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    const double hz = 0.5 * z;
    const double one_minus_hz = 1.0 - hz;
    const double hz_err = (1.0 - one_minus_hz) - hz;  // exact rounding error
    return one_minus_hz + (hz_err + (z * r - x * y));
}

// ---------------------------------------------------------------------------
// atan kernel (fdlibm s_atan.c reduction and polynomial).
// ---------------------------------------------------------------------------

/// atan(t + d) as a normalised double-double, for finite t >= 0 and a low
/// part |d| <~ ulp(t). The low part enters as atan'(t) * d = d / (1 + t^2).
DD atan_kernel(double t, double d) {
    // atan(0.5), atan(1), atan(1.5): hi = correctly rounded, lo = remainder.
    constexpr double kAtanHi[3] = {
        0x1.dac670561bb4fp-2,  // 4.63647609000806093515e-01
        0x1.921fb54442d18p-1,  // 7.85398163397448278999e-01
        0x1.f730bd281f69bp-1,  // 9.82793723247329054082e-01
    };
    constexpr double kAtanLo[3] = {
        0x1.a2b7f222f65e2p-56,  // 2.26987774529616870924e-17
        0x1.1a62633145c07p-55,  // 3.06161699786838301793e-17
        0x1.007887af0cbbdp-56,  // 1.39033110312309984516e-17
    };
    // atan(u) ~ u - u * (aT0 u^2 + aT1 u^4 + ... + aT10 u^22) for |u| <= 7/16.
    constexpr double aT0 = 0x1.555555555550dp-2;    //  3.33333333333329318027e-01
    constexpr double aT1 = -0x1.999999998ebc4p-3;   // -1.99999999998764832476e-01
    constexpr double aT2 = 0x1.24924920083ffp-3;    //  1.42857142725034663711e-01
    constexpr double aT3 = -0x1.c71c6fe231671p-4;   // -1.11111104054623557880e-01
    constexpr double aT4 = 0x1.745cdc54c206ep-4;    //  9.09088713343650656196e-02
    constexpr double aT5 = -0x1.3b0f2af749a6dp-4;   // -7.69187620504482999495e-02
    constexpr double aT6 = 0x1.10d66a0d03d51p-4;    //  6.66107313738753120669e-02
    constexpr double aT7 = -0x1.dde2d52defd9ap-5;   // -5.83357013379057348645e-02
    constexpr double aT8 = 0x1.97b4b24760debp-5;    //  4.97687799461593236017e-02
    constexpr double aT9 = -0x1.2b4442c6a6c2fp-5;   // -3.65315727442169155270e-02
    constexpr double aT10 = 0x1.0ad3ae322da11p-6;   //  1.62858201153657823623e-02

    // Reduce: atan(t) = atan(c_id) + atan(u), |u| <= 7/16.
    int id;     // -1: no breakpoint; 0, 1, 2: atan(0.5), atan(1), atan(1.5); 3: pi/2
    double u;
    if (t < 0.4375) {  // [0, 7/16)
        id = -1;
        u = t;
    } else if (t < 0.6875) {  // [7/16, 11/16): u = (t - 0.5) / (1 + 0.5 t)
        id = 0;
        u = (2.0 * t - 1.0) / (2.0 + t);
    } else if (t < 1.1875) {  // [11/16, 19/16): u = (t - 1) / (1 + t)
        id = 1;
        u = (t - 1.0) / (t + 1.0);
    } else if (t < 2.4375) {  // [19/16, 39/16): u = (t - 1.5) / (1 + 1.5 t)
        id = 2;
        u = (t - 1.5) / (1.0 + 1.5 * t);
    } else {  // [39/16, inf): atan(t) = pi/2 + atan(-1/t)
        id = 3;
        u = -1.0 / t;
    }

    const double z = u * u;
    const double w = z * z;
    const double s_odd = z * (aT0 + w * (aT2 + w * (aT4 + w * (aT6 + w * (aT8 + w * aT10)))));
    const double s_even = w * (aT1 + w * (aT3 + w * (aT5 + w * (aT7 + w * aT9))));
    const double poly = u * (s_odd + s_even);  // atan(u) = u - poly
    const double correction = d / (1.0 + t * t);

    if (id < 0) {
        return two_sum(u, correction - poly);
    }
    const double base_hi = id == 3 ? kPio2 : kAtanHi[id];
    const double base_lo = id == 3 ? 0.5 * kPiLo : kAtanLo[id];
    const DD head = two_sum(base_hi, u);  // exact
    const double tail = head.lo + ((base_lo + correction) - poly);
    return two_sum(head.hi, tail);
}

// ---------------------------------------------------------------------------
// atan2: table-driven reduction (the record's three Euler angles every tick).
// ---------------------------------------------------------------------------

/// atan2(ay, ax) for finite ay, ax > 0 with 2^-60 <= ay/ax <= 2^60; the angle
/// is taken from the negative x axis when x_negative (pi - atan(ay/ax)).
///
/// The octant's ratio r = n / m in (0, 1] (n, m = the smaller and the larger
/// of ay, ax) is reduced to the nearest of 65 table points c = i / 64 when
/// r >= 1/64: atan(r) = atan(c) + atan(t), t = (n - c m) / (m + c n),
/// 0 <= t < 1/128 for i = 1 and |t| <= 1/128 + an ulp above. The numerator
/// is exact to one rounding (m split so that c m_hi is exact; then
/// Sterbenz), so t is within ~1.5 ulp of itself, which is at most a third of
/// the result: a few tenths of its ulp. Below 1/64 (c = 0) t is the quotient
/// itself, whose rounding would be half the result's error: its remainder d
/// is carried (Dekker's product) and the result rounded once. The series to
/// t^9 leaves < 2^-63 of t (t^11 / 11 at t = 2^-6). atan(c) is a
/// double-double (tools/derive_atan_table.py). Two divisions against the
/// four of the double-double quotient and the fdlibm reduction that asin
/// keeps; measured within 1 ulp of glibc (tests/c/test_math_portable.cpp).
double atan2_general(double ay, double ax, bool x_negative) {
    static constexpr double kAtanTabHi[65] = {
        0x0.0p+0, 0x1.fff555bbb729bp-7, 0x1.ffd55bba97625p-6,
        0x1.7fb818430da2ap-5, 0x1.ff55bb72cfdeap-5, 0x1.3f59f0e7c559dp-4,
        0x1.7ee182602f10fp-4, 0x1.be39ebe6f07c3p-4, 0x1.fd5ba9aac2f6ep-4,
        0x1.1e1fafb043727p-3, 0x1.3d6eee8c6626cp-3, 0x1.5c9811e3ec26ap-3,
        0x1.7b97b4bce5b02p-3, 0x1.9a6a8e96c8626p-3, 0x1.b90d7529260a2p-3,
        0x1.d77d5df205736p-3, 0x1.f5b75f92c80ddp-3, 0x1.09dc597d86362p-2,
        0x1.18bf5a30bf178p-2, 0x1.278372057ef46p-2, 0x1.362773707ebccp-2,
        0x1.44aa436c2af0ap-2, 0x1.530ad9951cd4ap-2, 0x1.614840309cfe2p-2,
        0x1.6f61941e4def1p-2, 0x1.7d5604b63b3f7p-2, 0x1.8b24d394a1b25p-2,
        0x1.98cd5454d6b18p-2, 0x1.a64eec3cc23fdp-2, 0x1.b3a911da65c6cp-2,
        0x1.c0db4c94ec9f0p-2, 0x1.cde53432c1351p-2, 0x1.dac670561bb4fp-2,
        0x1.e77eb7f175a34p-2, 0x1.f40dd0b541418p-2, 0x1.0039c73c1a40cp-1,
        0x1.0657e94db30d0p-1, 0x1.0c6145b5b43dap-1, 0x1.1255d9bfbd2a9p-1,
        0x1.1835a88be7c13p-1, 0x1.1e00babdefeb4p-1, 0x1.23b71e2cc9e6ap-1,
        0x1.2958e59308e31p-1, 0x1.2ee628406cbcap-1, 0x1.345f01cce37bbp-1,
        0x1.39c391cd4171ap-1, 0x1.3f13fb89e96f4p-1, 0x1.445065b795b56p-1,
        0x1.4978fa3269ee1p-1, 0x1.4e8de5bb6ec04p-1, 0x1.538f57b89061fp-1,
        0x1.587d81f732fbbp-1, 0x1.5d58987169b18p-1, 0x1.6220d115d7b8ep-1,
        0x1.66d663923e087p-1, 0x1.6b798920b3d99p-1, 0x1.700a7c5784634p-1,
        0x1.748978fba8e0fp-1, 0x1.78f6bbd5d315ep-1, 0x1.7d528289fa093p-1,
        0x1.819d0b7158a4dp-1, 0x1.85d69576cc2c5p-1, 0x1.89ff5ff57f1f8p-1,
        0x1.8e17aa99cc05ep-1, 0x1.921fb54442d18p-1,
    };
    static constexpr double kAtanTabLo[65] = {
        0x0.0p+0, -0x1.220c39d4dff50p-61, -0x1.5ec431444912cp-60,
        -0x1.86ef8f794f105p-63, -0x1.c934d86d23f1dp-60, 0x1.ac4ce285df847p-58,
        -0x1.cfb654c0c3d98p-58, 0x1.f7b8f29a05987p-58, -0x1.cd37686760c17p-59,
        -0x1.b485914dacf8cp-59, 0x1.61a3b0ce9281bp-57, -0x1.054ab2c010f3dp-58,
        0x1.347b0b4f881cap-58, 0x1.cf601e7b4348ep-59, 0x1.17b10d2e0e5abp-61,
        0x1.c648d1534597ep-57, 0x1.8ab6e3cf7afbdp-57, 0x1.62e47390cb865p-56,
        0x1.30ca4748b1bf9p-57, -0x1.077cdd36dfc81p-56, -0x1.963a544b672d8p-57,
        -0x1.5d5e43c55b3bap-56, -0x1.2566480884082p-57, -0x1.a725715711f00p-56,
        -0x1.c63aae6f6e918p-56, 0x1.69c885c2b249ap-56, 0x1.b6d0ba3748fa8p-56,
        0x1.9e6c988fd0a77p-56, -0x1.24dec1b50b7ffp-56, 0x1.ae187b1ca5040p-56,
        -0x1.cc1ce70934c34p-56, -0x1.a2cfa4418f1adp-56, 0x1.a2b7f222f65e2p-56,
        0x1.0e53dc1bf3435p-56, -0x1.a3992dc382a23p-57, -0x1.b32c949c9d593p-55,
        -0x1.d5b495f6349e6p-56, 0x1.974fa13b5404fp-58, -0x1.2bdaee1c0ee35p-58,
        0x1.c621cec00c301p-55, -0x1.928df287a668fp-58, 0x1.c421c9f38224ep-57,
        -0x1.09e73b0c6c087p-56, 0x1.c5d5e9ff0cf8dp-55, 0x1.1021137c71102p-55,
        -0x1.2304331d8bf46p-55, 0x1.ecf8b492644f0p-56, -0x1.f76d0163f79c8p-56,
        0x1.2419a87f2a458p-56, 0x1.4a33dbeb3796cp-55, -0x1.1bb74abda520cp-55,
        -0x1.5e5c9d8c5a950p-56, 0x1.0028e4bc5e7cap-57, -0x1.2b785350ee8c1p-57,
        -0x1.6ea6febe8bbbap-56, -0x1.a80386188c50ep-55, -0x1.8c34d25aadef6p-56,
        0x1.7b2a6165884a1p-59, 0x1.406a089803740p-55, 0x1.560821e2f3aa9p-55,
        -0x1.bf76229d3b917p-56, 0x1.6b66e7fc8b8c3p-57, -0x1.55b9a5e177a1bp-55,
        -0x1.ec182ab042f61p-56, 0x1.1a62633145c07p-55,
    };
    // atan(t) = t - q, q = t^3/3 - t^5/5 + t^7/7 - t^9/9 (Taylor; |t| < 2^-6)
    constexpr double kThird = 1.0 / 3.0;
    constexpr double kFifth = 1.0 / 5.0;
    constexpr double kSeventh = 1.0 / 7.0;
    constexpr double kNinth = 1.0 / 9.0;
    const bool swapped = ay > ax;  // the angle from the y axis: pi/2 -+ atan(ax/ay)
    double n = swapped ? ax : ay;
    double m = swapped ? ay : ax;
    // Bring m into [2^-500, 2^500] by an exact power-of-two scaling of both
    // (n stays normal, n >= 2^-60 m), so that no product below under- or
    // overflows.
    if (m > 0x1p500) {
        m *= 0x1p-600;
        n *= 0x1p-600;
    } else if (m < 0x1p-500) {
        m *= 0x1p600;
        n *= 0x1p600;
    }
    const double r = n / m;
    // the nearest table point, 1..64, for r >= 1/64; 0 below
    const int i = r < 0x1p-6 ? 0 : static_cast<int>(r * 64.0 + 0.5);
    double t = r;
    double d = 0.0;  // t + d = n / m when i == 0
    if (i > 0) {
        const double c = static_cast<double>(i) * 0x1p-6;
        // m = m_hi + m_lo, m_hi with 46 significant bits: c (<= 6 significant
        // bits, or 1 for i = 64) times m_hi is exact, and so is c m_lo
        const double m_hi = from_bits(bits_of(m) & ~std::uint64_t{0x7F});
        const double m_lo = m - m_hi;
        t = ((n - c * m_hi) - c * m_lo) / (m + c * n);
    } else {
        // n - r m exactly (two_prod; n - p.hi is exact by Sterbenz)
        const DD p = two_prod(r, m);
        d = ((n - p.hi) - p.lo) / m;
    }
    const double z = t * t;
    const double q = t * z * (kThird - z * (kFifth - z * (kSeventh - z * kNinth)));
    // angle = K + s atan(r): K = 0, s = +1 in the first octant; K = pi/2,
    // s = -1 (x > 0) or +1 (x < 0) when swapped; K = pi, s = -1 for x < 0.
    // (d: atan(t + d) = atan(t) + d to far below an ulp, d being ~ulp(t))
    if (!swapped && !x_negative) {
        const DD head = two_sum(kAtanTabHi[i], t);  // exact
        return head.hi + (head.lo + ((kAtanTabLo[i] + d) - q));
    }
    const double k_hi = swapped ? kPio2 : kPi;
    const double k_lo = swapped ? 0.5 * kPiLo : kPiLo;
    const double a_lo = kAtanTabLo[i] + ((t + d) - q);  // atan(r) - kAtanTabHi[i]
    if (swapped == x_negative) {  // K + atan(r)
        const DD head = two_sum(k_hi, kAtanTabHi[i]);  // exact
        return head.hi + (head.lo + (k_lo + a_lo));
    }
    const DD head = two_sum(k_hi, -kAtanTabHi[i]);  // K - atan(r), exact
    return head.hi + (head.lo + (k_lo - a_lo));
}

}  // namespace

// ---------------------------------------------------------------------------
// Public functions.
// ---------------------------------------------------------------------------

double sin(double x) {
    if (!is_finite(x)) {
        return kNaN;
    }
    if (magnitude(x) < 0x1p-27) {
        return x;  // sin x = x (1 - x^2/6), x^2/6 < 2^-56: rounds to x; keeps -0
    }
    const Reduced r = reduce(x);
    switch (r.quadrant) {
        case 0u: return kernel_sin(r.hi, r.lo);
        case 1u: return kernel_cos(r.hi, r.lo);
        case 2u: return -kernel_sin(r.hi, r.lo);
        default: return -kernel_cos(r.hi, r.lo);
    }
}

double cos(double x) {
    if (!is_finite(x)) {
        return kNaN;
    }
    if (magnitude(x) < 0x1p-27) {
        return 1.0;  // cos x = 1 - x^2/2, x^2/2 < 2^-55: rounds to 1
    }
    const Reduced r = reduce(x);
    switch (r.quadrant) {
        case 0u: return kernel_cos(r.hi, r.lo);
        case 1u: return -kernel_sin(r.hi, r.lo);
        case 2u: return -kernel_cos(r.hi, r.lo);
        default: return kernel_sin(r.hi, r.lo);
    }
}

void sincos(double x, double* s, double* c) {
    if (!is_finite(x)) {
        *s = kNaN;
        *c = kNaN;
        return;
    }
    if (magnitude(x) < 0x1p-27) {
        *s = x;
        *c = 1.0;
        return;
    }
    const Reduced r = reduce(x);
    const double ks = kernel_sin(r.hi, r.lo);
    const double kc = kernel_cos(r.hi, r.lo);
    switch (r.quadrant) {
        case 0u: *s = ks; *c = kc; break;
        case 1u: *s = kc; *c = -ks; break;
        case 2u: *s = -ks; *c = -kc; break;
        default: *s = -kc; *c = ks; break;
    }
}

double atan2(double y, double x) {
    const bool y_negative = sign_bit(y);
    const bool x_negative = sign_bit(x);  // true for -0: atan2(+-0, -0) = +-pi
    const double ay = magnitude(y);
    const double ax = magnitude(x);
    // The common case first, in one test: both finite, x non-zero and
    // 2^-60 <= |y/x| <= 2^60 (so y is non-zero; a NaN fails every
    // comparison). It is the last branch of the chain below, taken early.
    if (ax > 0.0 && ax < kInf && ay < kInf && ay * 0x1p60 >= ax && ax * 0x1p60 >= ay) {
        const double angle = atan2_general(ay, ax, x_negative);
        return y_negative ? -angle : angle;
    }
    if (is_nan(x) || is_nan(y)) {
        return kNaN;
    }

    // angle = atan2(|y|, x) in [0, pi]; the sign of y is applied at the end.
    double angle;
    if (ay == 0.0) {
        angle = x_negative ? kPi : 0.0;
    } else if (ax == 0.0) {
        angle = kPio2;
    } else if (ax == kInf) {
        if (ay == kInf) {
            angle = x_negative ? k3Pio4 : kPio4;
        } else {
            angle = x_negative ? kPi : 0.0;
        }
    } else if (ay == kInf) {
        angle = kPio2;
    } else if (ay > ax * 0x1p60) {
        // |y/x| > 2^60: pi/2 -+ |x/y| rounds to kPio2 (kPio2 is 0.28 ulp
        // below pi/2). ax * 2^60 is exact, or overflows when the ratio is
        // small anyway.
        angle = kPio2;
    } else if (ay * 0x1p60 < ax) {
        // |y/x| < 2^-60: atan(q) = q (1 - q^2/3) rounds like q; pi - q rounds
        // to kPi (kPi is 0.28 ulp below pi). ay * 2^60 is exact or overflows.
        angle = x_negative ? kPi : ay / ax;
    } else {
        angle = atan2_general(ay, ax, x_negative);
    }
    return y_negative ? -angle : angle;
}

double asin(double x) {
    if (is_nan(x)) {
        return kNaN;
    }
    const double ax = magnitude(x);
    if (ax > 1.0) {
        return kNaN;
    }
    if (ax == 1.0) {
        return sign_bit(x) ? -kPio2 : kPio2;
    }
    if (ax < 0x1p-26) {
        return x;  // asin x = x (1 + x^2/6), x^2/6 < 2^-54: rounds to x; keeps -0
    }
    // asin x = atan(ax / sqrt(1 - ax^2)), every step as a double-double.
    // 1 - ax^2 = one_minus.hi + (one_minus.lo - sq.lo), exact up to the last
    // (tiny) addition.
    const DD sq = two_prod(ax, ax);
    const DD one_minus = two_sum(1.0, -sq.hi);
    const double rad_hi = one_minus.hi;
    const double rad_lo = one_minus.lo - sq.lo;
    // sqrt(rad_hi + rad_lo) = root + root_lo, one Newton step in double-double
    // (rad_hi - root^2 is exact: two_prod, then Sterbenz).
    const double root = sqrt(rad_hi);
    const DD root_sq = two_prod(root, root);
    const double root_lo = (((rad_hi - root_sq.hi) - root_sq.lo) + rad_lo) / (2.0 * root);
    // ax / (root + root_lo) = t + d.
    const double t = ax / root;
    const DD p = two_prod(t, root);
    const double d = (((ax - p.hi) - p.lo) - t * root_lo) / root;
    const DD a = atan_kernel(t, d);
    const double angle = a.hi + a.lo;
    return sign_bit(x) ? -angle : angle;
}

}  // namespace pyins::pmath
