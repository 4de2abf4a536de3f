// The Eigen types of the compiled loops (freefloat::sim), without Pinocchio.
#pragma once

#include <Eigen/Core>

namespace freefloat::sim {

using Vec = Eigen::VectorXd;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;

}  // namespace freefloat::sim
