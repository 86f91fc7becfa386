/* softfp_check.c: 60,000 double sums and differences, printed as hex for
 * tools/compare_embedded.py to check against the host's IEEE 754 results.
 * Operands from a 64-bit LCG: every exponent difference 0..63, signs mixed,
 * the larger operand's significand random, zero, small (a power of two or
 * just above) or all ones (just below the next power): the cases where a
 * difference loses its leading bits. Built on every target; on the
 * Cortex-M4F the doubles are soft and go through csrc/port/arm_softfp_add.c
 * (linked by pyins_core), where libgcc alone gets ~1 in 1,000 of these
 * wrong (docs/embedded.md, "Soft doubles on the M4F").
 * Prints "op a b result" per case (op 0: a - b, 1: a + b, 2: b - a), then DONE. */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define CASES 60000

static double from_bits(uint64_t u) {
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

static void put_bits(double x) {
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    printf(" %08lx%08lx", (unsigned long)(u >> 32), (unsigned long)(u & 0xffffffffu));
}

static uint64_t next(uint64_t *s) {
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s;
}

int main(void) {
    uint64_t s = 11u;
    int i;
    for (i = 0; i < CASES; ++i) {
        const int op = i % 3;
        uint64_t r = next(&s);
        const uint64_t ea = 900u + ((r >> 57) & 127u);
        uint64_t fa = (i & 4) ? ((r >> 3) & 0xfffffffffffffull) : ((i & 8) ? 0u : ((r >> 3) & 0xffu));
        volatile double a, b, res;
        uint64_t eb;
        if (i & 16) fa = 0xfffffffffffffull - ((r >> 5) & 0xffu);
        a = from_bits((ea << 52) | fa | ((i & 32) ? (1ull << 63) : 0u));
        r = next(&s);
        eb = ea - (r >> 58);
        b = from_bits((eb << 52) | ((r >> 8) & 0xfffffffffffffull) | ((i & 64) ? (1ull << 63) : 0u));
        res = op == 0 ? a - b : (op == 1 ? a + b : b - a);
        printf("%d", op);
        put_bits(a);
        put_bits(b);
        put_bits(res);
        printf("\n");
    }
    printf("DONE\n");
    return 0;
}
