// types.hpp: the fixed-size value types of the core.
//
// Eigen fixed-size vectors and matrices only (never MatrixXd): the core must
// not allocate (built with EIGEN_NO_MALLOC), and on the host Eigen takes its
// scalar path (EIGEN_DONT_VECTORIZE) so the bits equal the Cortex-M build's.
#pragma once

#include <cmath>

#include <Eigen/Core>

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
