#!/usr/bin/env python3
"""Print the arctangent table of csrc/src/math_portable.cpp (atan2).

atan(i / 64) for i = 0..64 as a double-double: hi = the correctly rounded
double, lo = the remainder atan(i / 64) - hi rounded to a double, both as
C99 hex-float literals. The kernel reduces atan(r) = atan(c) + atan((r - c)
/ (1 + r c)) with c = i / 64 the table point nearest r (|r - c| <= 1/128),
which leaves four terms of the series (a table-driven reduction: Muller,
"Elementary Functions", 3rd ed., 2016, ch. 6).

The values come from Python's decimal module at 80 digits: the argument
halved three times (atan x = 2 atan(x / (1 + sqrt(1 + x^2)))), then the
Taylor series to 1e-80. No dependency beyond the standard library.

    python3 tools/derive_atan_table.py
"""
from decimal import Decimal, getcontext
from fractions import Fraction

N = 64  # table points per unit of the ratio


def atan_decimal(x):
    """atan(x) for 0 <= x <= 1 to ~75 digits."""
    halvings = 3
    for _ in range(halvings):
        x = x / (1 + (1 + x * x).sqrt())
    term, total, k, x2 = x, Decimal(0), 0, x * x
    while abs(term) > Decimal("1e-80"):
        total += term / (2 * k + 1)
        term = -term * x2
        k += 1
    return total * (2 ** halvings)


def nearest_double(d):
    """The double nearest the decimal d (correctly rounded through Fraction)."""
    return float(Fraction(d))


def main():
    getcontext().prec = 80
    hi, lo = [], []
    for i in range(N + 1):
        a = atan_decimal(Decimal(i) / N)
        h = nearest_double(a)
        hi.append(h)
        lo.append(nearest_double(a - Decimal(h)))
    for name, vals in (("kAtanTabHi", hi), ("kAtanTabLo", lo)):
        print(f"constexpr double {name}[{N + 1}] = {{")
        for k in range(0, N + 1, 3):
            print("    " + " ".join(f"{float.hex(v)}," for v in vals[k:k + 3]))
        print("};")


if __name__ == "__main__":
    main()
