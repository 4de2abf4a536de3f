// The Eigen types of the compiled loops (freefloat::sim), without Pinocchio.
#pragma once

#include <Eigen/Core>

namespace freefloat::sim {

using Vec = Eigen::VectorXd;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
// A placement as a homogeneous transform [R p; 0 1] (4, 4), row-major as numpy hands it over.
using Pose = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;

}  // namespace freefloat::sim
