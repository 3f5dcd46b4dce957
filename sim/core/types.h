// Scalar and fixed-size vector types shared by the whole simulator.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace shellmpm {

#ifdef SHELLMPM_DOUBLE
using Real = double;  ///< simulation scalar; build with -DSHELLMPM_DOUBLE=ON for double
#else
using Real = float;  ///< simulation scalar (float by default)
#endif

using Vec2 = Eigen::Matrix<Real, 2, 1>;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat2 = Eigen::Matrix<Real, 2, 2>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Vec3d = Eigen::Matrix<double, 3, 1>;
using Mat3d = Eigen::Matrix<double, 3, 3>;
using Vec3i = Eigen::Matrix<int, 3, 1>;

}  // namespace shellmpm
