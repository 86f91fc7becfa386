// angle.hpp: angles wrapped to one turn, for the firmware and the plant.
//
// Mirrored by pyins/reference/angle.py. Header-only (inline) so that the
// host-only plant (csrc/plant/plant.cpp) wraps its encoder reading with the
// very function the firmware uses, without linking the core's internals.
#pragma once

#include <cmath>

#include "units.hpp"

namespace pyins::angle {

/// Angle in [0, 2 pi) for any finite input. std::floor is exact, so this is
/// bit-portable.
inline double wrap_two_pi(double a) {
    if (a >= 0.0 && a < kTwoPi) {
        return a;
    }
    double w = a - kTwoPi * std::floor(a / kTwoPi);
    // Rounding can land on 2 pi or a hair below 0 (the angle is then a whole
    // number of turns), and beyond |a| ~ 1e16 the ulp of a exceeds 2 pi and
    // w means nothing (found by tests/fuzz): all of these wrap to 0.
    if (!(w >= 0.0 && w < kTwoPi)) {
        w = 0.0;
    }
    return w;
}

/// Angle in (-pi, pi] for an input within (-3 pi, 3 pi].
inline double wrap_pi(double a) {
    if (a > kPi) {
        return a - kTwoPi;
    }
    if (a <= -kPi) {
        return a + kTwoPi;
    }
    return a;
}

}  // namespace pyins::angle
