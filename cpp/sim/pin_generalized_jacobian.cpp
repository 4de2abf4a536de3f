// The definition of pin_generalized_jacobian.hpp.
#include <Eigen/Cholesky>

#include "pin_generalized_jacobian.hpp"

namespace freefloat::sim {

void generalized_jacobian(const Model& m, Workspace& w, const Vec& q, const Vec& v, int base_frame,
                          const std::vector<int>& ee_frames, int n, GeneralizedJacobian& out) {
  CentroidalFrames c;
  centroidal_frames(m, w, q, v, base_frame, ee_frames, n, c);
  const int k = static_cast<int>(ee_frames.size());
  // H0^-1 [H0m | M]; H0 is symmetric positive definite, and the loop's unit already compiles
  // Eigen's Cholesky of a dynamic matrix (a 6 x 6 LDLT took that unit 2.5 s longer to compile).
  const Eigen::MatrixXd Y = Eigen::MatrixXd(c.H0).llt().solve(c.momentum);
  out.J0 = -Y.leftCols(n);
  out.base_twist = Y.col(n);
  out.Jstar.resize(6 * k, n);
  out.drift.resize(6 * k);
  Eigen::MatrixXd G(6, n + 1);  // J0E{e} Y, eq 78: v_E = v0 + w0 x (r_E - r0), w_E = w0
  for (int e = 0; e < k; ++e) {
    const Vec3 arm = c.ee_position[e] - c.base_position;
    for (int j = 0; j <= n; ++j) {
      G.col(j).head<3>() = Y.col(j).head<3>() + Vec3(Y.col(j).tail<3>()).cross(arm);
      G.col(j).tail<3>() = Y.col(j).tail<3>();
    }
    out.Jstar.middleRows(6 * e, 6) = c.ee_jacobian[e].rightCols(n) - G.leftCols(n);  // Jm: the joint columns, eq 76
    out.drift.segment<6>(6 * e) = G.col(n);
  }
}

}  // namespace freefloat::sim
