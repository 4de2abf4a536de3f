// generalized_jacobian.hpp's quantities of one state (dissertation eqs 69-89, the same numbers as
// freefloat.dynamics.gjm.GJMState) from Pinocchio's algorithms: the centroidal momentum matrix
// (ccrba) and the frame Jacobians. The base is treated as a free rigid body in 3-D whatever the
// root joint (a planar root is embedded in 3-D, as in gjm.compute): H0 is the locked robot's
// spatial inertia about the base CoM, H0m the momentum of unit joint rates at a still base link.
#pragma once

#include <pinocchio/algorithm/centroidal.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>

#include <vector>

#include "generalized_jacobian.hpp"
#include "pin_model.hpp"

namespace freefloat::sim {

// At state (q, v): `base_frame` is the base CoM frame, `ee_frames` the end-effector frames (their
// origins are the points E), n the actuated joints (the last n velocities).
inline void generalized_jacobian(const Model& m, Data& d, const Vec& q, const Vec& v, pinocchio::FrameIndex base_frame,
                                 const std::vector<int>& ee_frames, int n, GeneralizedJacobian& out) {
  const int k = static_cast<int>(ee_frames.size());
  pinocchio::ccrba(m, d, q, v);  // Ag, hg about the CoM (inertial axes), Ig, com
  pinocchio::computeJointJacobians(m, d, q);
  const Vec3 r0 = pinocchio::updateFramePlacement(m, d, base_frame).translation();
  const Vec3 c = d.com[0] - r0;  // system CoM from the base CoM
  // Columns [H0m | M]: [P; L about r0] of unit joint rates (still base link), then of the state.
  Eigen::MatrixXd momentum(6, n + 1);
  momentum.leftCols(n) = d.Ag.rightCols(n);
  momentum.col(n) = d.hg.toVector();
  for (int j = 0; j <= n; ++j) momentum.col(j).tail<3>() += c.cross(Vec3(momentum.col(j).head<3>()));
  const Eigen::Matrix<double, 6, 6> H0 = Inertia(d.Ig.mass(), c, d.Ig.inertia()).matrix();  // eq 23
  const Eigen::MatrixXd Y = H0.ldlt().solve(momentum);  // H0^-1 [H0m | M]
  out.J0 = -Y.leftCols(n);
  out.base_twist = Y.col(n);
  out.Jstar.resize(6 * k, n);
  out.drift.resize(6 * k);
  Eigen::Matrix<double, 6, Eigen::Dynamic> J = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, m.nv);
  Eigen::MatrixXd G(6, n + 1);  // J0E{e} Y, eq 78: v_E = v0 + w0 x (r_E - r0), w_E = w0
  for (int e = 0; e < k; ++e) {
    const Vec3 arm = pinocchio::updateFramePlacement(m, d, ee_frames[e]).translation() - r0;
    J.setZero();
    pinocchio::getFrameJacobian(m, d, ee_frames[e], pinocchio::LOCAL_WORLD_ALIGNED, J);
    for (int j = 0; j <= n; ++j) {
      G.col(j).head<3>() = Y.col(j).head<3>() + Vec3(Y.col(j).tail<3>()).cross(arm);
      G.col(j).tail<3>() = Y.col(j).tail<3>();
    }
    out.Jstar.middleRows(6 * e, 6) = J.rightCols(n) - G.leftCols(n);  // Jm: the joint columns, eq 76
    out.drift.segment<6>(6 * e) = G.col(n);
  }
}

}  // namespace freefloat::sim
