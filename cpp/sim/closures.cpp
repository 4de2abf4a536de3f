// The definitions of closures.hpp: the constrained dynamics of a tree with loop closures, on
// pin_plant.hpp's Pinocchio calls.
#include <stdexcept>

#include "closures.hpp"
#include "detumbling.hpp"  // pinv

namespace freefloat::sim {

static Mat3 skew(const Vec3& x) {
  Mat3 s;
  s << 0.0, -x.z(), x.y(), x.z(), 0.0, -x.x(), -x.y(), x.x(), 0.0;
  return s;
}

void ClosureRows::evaluate(const std::vector<ClosureSpec>& closures, const Model& m, Workspace& w, bool drift) {
  int rows = 0;
  for (const ClosureSpec& c : closures) rows += c.size();
  e.resize(rows);
  J.resize(rows, nv(m));
  gamma.resize(drift ? rows : 0);
  int r = 0;
  for (const ClosureSpec& c : closures) {
    frame_motion(m, w, c.joint1, c.placement1, one);
    frame_motion(m, w, c.joint2, c.placement2, two);
    const Mat3 R1t = one.rotation.transpose();
    const Vec3 dp = two.position - one.position, dp_dot = two.velocity - one.velocity;
    const Vec3 e_p = R1t * dp;
    e.segment<3>(r) = e_p;
    J.middleRows(r, 3) = R1t * (two.jacobian.topRows<3>() - one.jacobian.topRows<3>()) +
                         skew(e_p) * R1t * one.jacobian.bottomRows<3>();
    const Eigen::MatrixXd J_r = R1t * (two.jacobian.bottomRows<3>() - one.jacobian.bottomRows<3>());
    const Mat3 relative = R1t * two.rotation;
    const int k = static_cast<int>(c.rotation_rows.size());
    const Vec3 angle = k == 3 ? log3(relative) : Vec3(Vec3::UnitZ().cross(Vec3(relative.col(2))));
    for (int i = 0; i < k; ++i) {
      e[r + 3 + i] = angle[c.rotation_rows[i]];
      J.row(r + 3 + i) = J_r.row(c.rotation_rows[i]);
    }
    if (drift) {
      const Vec3& w1 = one.angular_velocity;
      const Vec3 dw = two.angular_velocity - w1;
      gamma.segment<3>(r) = R1t * (two.acceleration - one.acceleration - one.angular_acceleration.cross(dp) -
                                   2.0 * w1.cross(dp_dot) + w1.cross(w1.cross(dp)));
      const Vec3 g_r = R1t * (two.angular_acceleration - one.angular_acceleration - w1.cross(dw));
      for (int i = 0; i < k; ++i) gamma[r + 3 + i] = g_r[c.rotation_rows[i]];
    }
    r += c.size();
  }
}

int delassus_solve(const Eigen::MatrixXd& D, const Vec& rhs, Vec& out) {
  const int m = static_cast<int>(D.rows());
  if (m == 0) {
    out.resize(0);
    return 0;
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(D);
  if (llt.info() == Eigen::Success) {
    // 1 / trace(D^-1) <= lambda_min and trace(D) >= lambda_max: well conditioned for sure (a small
    // pivot is no bound: a singular D factored with a pivot^2 of 1.8e-12 times its diagonal).
    const double trace_inverse = llt.solve(Eigen::MatrixXd::Identity(m, m)).trace();
    if (trace_inverse > 0.0 && 1.0 / trace_inverse > kRedundant * D.trace()) {
      out = llt.solve(rhs);
      return m;
    }
  }
  int rank = 0;
  out = pinv(D, kRedundant, &rank) * rhs;
  return rank;
}

void ConstrainedDynamics::prepare(const Model& m, Workspace& w, const Vec& q, const Vec& v, bool with_wrenches) {
  kept = false;
  zero.setZero(nv(m));
  // CRBA in the WORLD convention also leaves the joint Jacobians (data.J) as
  // computeJointJacobians does, so that only the velocities and accelerations remain to compute.
  mass_matrix(m, w, q, true, M);
  rnea(m, w, q, v, zero, with_wrenches, h);
  forward_kinematics(m, w, q, v, zero);
  rows.evaluate(closures, m, w, true);
  llt.compute(M);
  if (llt.info() != Eigen::Success) throw std::overflow_error("the mass matrix is not positive definite");
  MinvJt = llt.solve(rows.J.transpose());
  D.noalias() = rows.J * MinvJt;
  if (!with_wrenches) {
    state_q = q;
    state_v = v;
    kept = true;
  }
}

void ConstrainedDynamics::solve(const Model& m, Workspace& w, const Vec& q, const Vec& v, const Vec& tau,
                                bool with_wrenches, Vec& a) {
  if (with_wrenches || !(kept && q == state_q && v == state_v)) prepare(m, w, q, v, with_wrenches);
  a_free = llt.solve(tau - h);
  rhs = -rows.gamma - 2.0 * baumgarte * (rows.J * v) - baumgarte * baumgarte * rows.e - rows.J * a_free;
  rank = delassus_solve(D, rhs, force);
  a = a_free + MinvJt * force;
  if (!a.allFinite()) throw std::overflow_error("constrained dynamics: accelerations are not finite");
}

}  // namespace freefloat::sim
