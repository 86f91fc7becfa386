/* arm_softfp_add.c: correctly rounded double addition and subtraction for
 * Arm targets whose doubles are computed in software (Cortex-M4F: the FPU is
 * single precision), around a rounding defect of libgcc's __adddf3.
 *
 * The defect (GCC 12.2.1's libgcc, ieee754-df.S, as Debian's
 * gcc-arm-none-eabi ships it; found by the embedded demo, docs/embedded.md,
 * "Soft doubles on the M4F"): when the operands' exponents differ by exactly
 * 33 and the smaller is subtracted (opposite signs), __adddf3 aligns it by
 * shifting its low word out entirely and keeps only a sticky bit of it; when
 * the difference then loses its leading bit (|x| near a power of two, e.g.
 * 1.0 - 1.4e-10) it is shifted left by one and takes its new last bit from
 * that sticky word, where the low word's top bit belonged. About half of
 * such results come out one unit in the last place too small. IEEE 754
 * (sec. 4.3) requires the correctly rounded result, which the host and the
 * Cortex-M7's FPU give; the core's same-bits-everywhere rule needs it too.
 *
 * pyins_softfp_dadd / _dsub / _drsub compute exactly that case here, in
 * integer arithmetic, and leave every other case to libgcc (whose results
 * are correct there: tools/compare_embedded.py checks 60,000 sums of every
 * exponent difference against the host on each build). The check costs a
 * few integer instructions per call. arm_softfp_wrap.c routes the
 * compiler's __aeabi_dadd/dsub/drsub calls here with -Wl,--wrap (the pyins_core
 * target carries those link options for the M4F build).
 *
 * Not the core (csrc/src): a port of the toolchain, built only where the
 * doubles are soft. No state, no heap, no I/O. */
#include <stdint.h>
#include <string.h>

#include "arm_softfp.h"

/* libgcc's routines, under their real names once --wrap is on */
PYINS_AAPCS double __real___aeabi_dadd(double a, double b);
PYINS_AAPCS double __real___aeabi_dsub(double a, double b);
PYINS_AAPCS double __real___aeabi_drsub(double a, double b);

#define FRAC_MASK 0x000fffffffffffffull
#define HIDDEN (1ull << 52)

static uint64_t bits_of(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}

static double double_of(uint64_t u) {
    double x;
    memcpy(&x, &u, sizeof x);
    return x;
}

/* |x| - |y| with the sign of x, both normal, exponent of x = exponent of y
 * + 33, correctly rounded to nearest, ties to even. The exact difference is
 * D = mx 2^33 - my (in units of y's last place), mx, my the 53-bit
 * significands; with my = myh 2^33 + myl (myl < 2^33),
 * D = H 2^33 + L, H = mx - myh - [myl > 0], L = (2^33 - myl) mod 2^33.
 * H >= 2^52 - 2^20 - 1: the result keeps x's exponent (H >= 2^52) or loses
 * one bit (then 2H + the top bit of L is the significand). */
static double sub_exp33(uint64_t ux, uint64_t uy) {
    const uint64_t mx = (ux & FRAC_MASK) | HIDDEN;
    const uint64_t my = (uy & FRAC_MASK) | HIDDEN;
    const uint64_t myh = my >> 33;
    const uint64_t myl = my & ((1ull << 33) - 1u);
    uint64_t h = mx - myh;
    uint64_t l = 0u;
    uint64_t mant;
    uint64_t rem;
    uint64_t half;
    uint64_t e = (ux >> 52) & 0x7ffu;
    if (myl != 0u) {
        h -= 1u;
        l = (1ull << 33) - myl;
    }
    if (h >= HIDDEN) {
        mant = h;
        rem = l;
        half = 1ull << 32;
    } else {
        mant = (h << 1) | (l >> 32);
        rem = l & 0xffffffffull;
        half = 1ull << 31;
        e -= 1u;
    }
    if (rem > half || (rem == half && (mant & 1u) != 0u)) {
        mant += 1u;
        if (mant == (HIDDEN << 1)) {
            mant >>= 1;
            e += 1u;
        }
    }
    return double_of((ux & (1ull << 63)) | (e << 52) | (mant & FRAC_MASK));
}

#define SIGN (1ull << 63)

/* The high word of x: sign, exponent and the top of the significand. */
static inline uint32_t high(double x) {
    return (uint32_t)(bits_of(x) >> 32);
}

/* The quick test made on every call (a few instructions): the operands
 * hb's sign flip applied, of opposite signs with exponents 33 apart. */
static inline int maybe_exp33(uint32_t ha, uint32_t hb) {
    const uint32_t d = ((ha >> 20) & 0x7ffu) - ((hb >> 20) & 0x7ffu) + 33u;
    return ((ha ^ hb) & 0x80000000u) != 0u && (d == 0u || d == 66u);
}

/* x + y (bit patterns) after the quick test passed: the correctly rounded
 * result when both are normal and finite; else 0 (*done = 0). */
static double exp33_sum(uint64_t ux, uint64_t uy, int *done) {
    const uint32_t ex = (uint32_t)(ux >> 52) & 0x7ffu;
    const uint32_t ey = (uint32_t)(uy >> 52) & 0x7ffu;
    *done = !(ex == 0u || ey == 0u || ex == 0x7ffu || ey == 0x7ffu);
    if (*done == 0) {
        return 0.0;
    }
    return ex > ey ? sub_exp33(ux, uy) : sub_exp33(uy, ux);
}

/* The slow paths, out of line so that the quick one saves no register and
 * ends in a tail call. */
__attribute__((noinline)) PYINS_AAPCS static double dadd_exp33(double a, double b) {
    int done;
    const double r = exp33_sum(bits_of(a), bits_of(b), &done);
    return done ? r : __real___aeabi_dadd(a, b);
}

__attribute__((noinline)) PYINS_AAPCS static double dsub_exp33(double a, double b) {
    int done;
    const double r = exp33_sum(bits_of(a), bits_of(b) ^ SIGN, &done);
    return done ? r : __real___aeabi_dsub(a, b);
}

__attribute__((noinline)) PYINS_AAPCS static double drsub_exp33(double a, double b) {
    int done;
    const double r = exp33_sum(bits_of(b), bits_of(a) ^ SIGN, &done);
    return done ? r : __real___aeabi_drsub(a, b);
}

PYINS_AAPCS double pyins_softfp_dadd(double a, double b) {
    return maybe_exp33(high(a), high(b)) ? dadd_exp33(a, b) : __real___aeabi_dadd(a, b);
}

/* a - b */
PYINS_AAPCS double pyins_softfp_dsub(double a, double b) {
    return maybe_exp33(high(a), high(b) ^ 0x80000000u) ? dsub_exp33(a, b) : __real___aeabi_dsub(a, b);
}

/* b - a */
PYINS_AAPCS double pyins_softfp_drsub(double a, double b) {
    return maybe_exp33(high(b), high(a) ^ 0x80000000u) ? drsub_exp33(a, b) : __real___aeabi_drsub(a, b);
}
