// types.hpp: the fixed-size value types of the core.
//
// Eigen fixed-size vectors and matrices only (never MatrixXd): the core must
// not allocate (built with EIGEN_NO_MALLOC), and on the host Eigen takes its
// scalar path (EIGEN_DONT_VECTORIZE) so the bits equal the Cortex-M build's.
#pragma once

#include <cmath>

#include <Eigen/Core>

/// On the host the per-tick strapdown update inlines every call it makes
/// (GCC/Clang `flatten`: 990 -> 915 instructions per navigation tick); the
/// Cortex-M builds keep the calls, their 64 KiB text budget being the
/// tighter limit there (flattened, the M7 core grows by ~850 bytes). Inlining
/// changes no operation, so the bits are the same either way.
#if defined(__ARM_ARCH) || !defined(__GNUC__)
#define PYINS_HOT_FLATTEN
#define PYINS_HOT_INLINE
#else
#define PYINS_HOT_FLATTEN [[gnu::flatten]]
#define PYINS_HOT_INLINE [[gnu::always_inline]] inline
#endif

namespace pyins {

using Vec3 = Eigen::Matrix<double, 3, 1>;
using Mat3 = Eigen::Matrix<double, 3, 3>;

/// Hamilton quaternion, scalar first. quat_ab rotates a vector from b to a:
/// v_a = q (x) v_b (x) conj(q).
struct Quat {
    double w;
    double x;
    double y;
    double z;
};

/// All three components of a C array (a pyins_config or pyins_sample field) finite.
inline bool finite3(const double v[3]) {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

}  // namespace pyins
