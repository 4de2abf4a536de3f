// Loop closures on a Pinocchio tree (freefloat.dynamics.closures, the numpy reference): a closure's
// rows with exact Jacobian and drift (closure.py: frame_motion, evaluate, stacked), and the
// constrained dynamics through the Delassus matrix (constrained.py: solve, delassus_solve),
//   M a + h = tau + J^T lambda,   J a = -gamma - 2 beta J v - beta^2 e,
//   lambda = D^+ (rhs - J M^-1 (tau - h)),  D = J M^-1 J^T,
// on Pinocchio's CRBA, RNEA (with the external wrenches) and joint Jacobians, solved with Eigen:
// no constraint-dynamics header (they are heavy to compile), the same numbers as the reference.
#pragma once

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/spatial.hpp>  // log3

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <stdexcept>
#include <string>
#include <vector>

#include "pin_model.hpp"

namespace freefloat::sim {

using Matrix6x = Data::Matrix6x;

// closures.constrained.REDUNDANT: relative eigenvalue below which a Delassus direction carries no force.
constexpr double kRedundant = 1e-12;

// One closure (closure.Closure): frame 1 = placement1 on joint1, frame 2 = placement2 on joint2;
// rotation_rows: the stopped rows of the relative angular velocity in frame 1's axes (ClosureKind).
struct Closure {
  JointIndex joint1 = 0, joint2 = 0;
  SE3 placement1 = SE3::Identity(), placement2 = SE3::Identity();
  std::vector<int> rotation_rows;

  int size() const { return 3 + static_cast<int>(rotation_rows.size()); }
};

// closure.FrameMotion: world axes, accelerations at zero joint acceleration, jacobian [linear; angular].
struct FrameMotion {
  SE3 pose;
  Vec3 velocity, angular_velocity, acceleration, angular_acceleration;
  Matrix6x jacobian;
};

// closure.frame_motion; `d` must hold what closure.kinematics leaves: placements, velocities,
// accelerations at zero joint acceleration and the joint Jacobians (ConstrainedDynamics::prepare).
inline void frame_motion(const Model& m, Data& d, JointIndex joint, const SE3& placement, FrameMotion& out) {
  out.pose = d.oMi[joint] * placement;
  const Mat3& R = out.pose.rotation();
  const pinocchio::Motion velocity = placement.actInv(d.v[joint]), acc = placement.actInv(d.a[joint]);
  out.velocity = R * velocity.linear();
  out.angular_velocity = R * velocity.angular();
  out.acceleration = R * (acc.linear() + velocity.angular().cross(velocity.linear()));
  out.angular_acceleration = R * acc.angular();
  out.jacobian.setZero(6, m.nv);
  pinocchio::getFrameJacobian(m, d, joint, placement, pinocchio::LOCAL_WORLD_ALIGNED, out.jacobian);
}

inline Mat3 skew(const Vec3& x) {
  Mat3 s;
  s << 0.0, -x.z(), x.y(), x.z(), 0.0, -x.x(), -x.y(), x.x(), 0.0;
  return s;
}

// The closures' rows stacked (closure.stacked): residual e (m,), Jacobian J (m, nv) and, when
// `drift`, gamma (m,), at the state kinematics() left in `d`.
struct ClosureRows {
  Vec e, gamma;
  Eigen::MatrixXd J;
  FrameMotion one, two;  // scratch

  void evaluate(const std::vector<Closure>& closures, const Model& m, Data& d, bool drift) {
    int rows = 0;
    for (const Closure& c : closures) rows += c.size();
    e.resize(rows);
    J.resize(rows, m.nv);
    gamma.resize(drift ? rows : 0);
    int r = 0;
    for (const Closure& c : closures) {
      frame_motion(m, d, c.joint1, c.placement1, one);
      frame_motion(m, d, c.joint2, c.placement2, two);
      const Mat3 R1t = one.pose.rotation().transpose();
      const Vec3 dp = two.pose.translation() - one.pose.translation(), dp_dot = two.velocity - one.velocity;
      const Vec3 e_p = R1t * dp;
      e.segment<3>(r) = e_p;
      J.middleRows(r, 3) = R1t * (two.jacobian.topRows<3>() - one.jacobian.topRows<3>()) +
                           skew(e_p) * R1t * one.jacobian.bottomRows<3>();
      const Eigen::MatrixXd J_r = R1t * (two.jacobian.bottomRows<3>() - one.jacobian.bottomRows<3>());
      const Mat3 relative = R1t * two.pose.rotation();
      const int k = static_cast<int>(c.rotation_rows.size());
      const Vec3 angle = k == 3 ? Vec3(pinocchio::log3(relative)) : Vec3(Vec3::UnitZ().cross(Vec3(relative.col(2))));
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
};

// constrained.delassus_solve: D^+ rhs for a symmetric positive semi-definite D, and its rank.
// Cholesky (of the upper triangle, as scipy's cho_factor) when D is well conditioned, otherwise
// an eigen-decomposition whose directions under kRedundant times the largest eigenvalue carry no force.
inline int delassus_solve(const Eigen::MatrixXd& D, const Vec& rhs, Vec& out) {
  const int m = static_cast<int>(D.rows());
  if (m == 0) {
    out.resize(0);
    return 0;
  }
  const Eigen::LLT<Eigen::MatrixXd, Eigen::Upper> llt(D);
  if (llt.info() == Eigen::Success) {
    const double pivot = llt.matrixU().toDenseMatrix().diagonal().minCoeff();
    if (pivot * pivot > kRedundant * D.diagonal().maxCoeff()) {
      out = llt.solve(rhs);
      return m;
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(D);
  const Vec& w = eig.eigenvalues();
  const double cut = kRedundant * std::max(w.maxCoeff(), 0.0);
  out.setZero(m);
  int rank = 0;
  for (int i = 0; i < m; ++i) {
    if (!(w[i] > cut)) continue;
    out += eig.eigenvectors().col(i) * (eig.eigenvectors().col(i).dot(rhs) / w[i]);
    ++rank;
  }
  return rank;
}

// constrained.solve with scratch kept between calls: the plant of a robot with loop closures. The
// part that does not depend on tau (M, h, the rows, the factors) is kept for the last state it was
// computed at without external wrenches: a law that prepare()s the state at the start of a period
// saves the integrator's first evaluation there that work (the same numbers: same q, v, model).
struct ConstrainedDynamics {
  std::vector<Closure> closures;
  double baumgarte = 0.0;  // beta, 1/s
  // Results of the last solve: closure forces lambda (m,), rank of D.
  Vec force;
  int rank = 0;
  // Scratch.
  ClosureRows rows;
  Eigen::MatrixXd M, MinvJt, D;
  Eigen::LLT<Eigen::MatrixXd, Eigen::Upper> llt;
  Vec h, zero, a_free, rhs;
  Vec state_q, state_v;  // the state M, h, rows, ... are for, when `kept`
  bool kept = false;

  bool empty() const { return closures.empty(); }
  // Forget the kept state (the model's numbers or the closures changed).
  void forget() { kept = false; }

  // M (symmetric), h = RNEA(q, v, 0, fext), the closures' rows, the Cholesky factor of M, M^-1 J^T
  // and D at (q, v), `d` left with what frame_motion reads; kept for solve() when `fext` is null.
  // Throws std::overflow_error when M is not positive definite.
  void prepare(const Model& m, Data& d, const Vec& q, const Vec& v, const std::vector<pinocchio::Force>* fext = nullptr) {
    kept = false;
    zero.setZero(m.nv);
    // CRBA in the WORLD convention also leaves the joint Jacobians (data.J) as
    // computeJointJacobians does, so that only the velocities and accelerations remain to compute.
    M = pinocchio::crba(m, d, ConstRef(q), pinocchio::Convention::WORLD).selfadjointView<Eigen::Upper>();
    if (fext == nullptr)
      h = pinocchio::rnea(m, d, ConstRef(q), ConstRef(v), ConstRef(zero));
    else
      h = pinocchio::rnea(m, d, ConstRef(q), ConstRef(v), ConstRef(zero), *fext);
    pinocchio::forwardKinematics(m, d, ConstRef(q), ConstRef(v), ConstRef(zero));
    rows.evaluate(closures, m, d, true);
    llt.compute(M);
    if (llt.info() != Eigen::Success) throw std::overflow_error("the mass matrix is not positive definite");
    MinvJt = llt.solve(rows.J.transpose());
    D.noalias() = rows.J * MinvJt;
    if (fext == nullptr) {
      state_q = q;
      state_v = v;
      kept = true;
    }
  }

  // The accelerations `a` at (q, v) under generalized forces tau (nv,) and the external wrenches
  // `fext` (one per joint, joint frames; null: none). Throws std::overflow_error with the
  // reference's message when M is not positive definite or `a` is not finite.
  void solve(const Model& m, Data& d, const Vec& q, const Vec& v, const Vec& tau,
             const std::vector<pinocchio::Force>* fext, Vec& a) {
    if (!(fext == nullptr && kept && q == state_q && v == state_v)) prepare(m, d, q, v, fext);
    a_free = llt.solve(tau - h);
    rhs = -rows.gamma - 2.0 * baumgarte * (rows.J * v) - baumgarte * baumgarte * rows.e - rows.J * a_free;
    rank = delassus_solve(D, rhs, force);
    a = a_free + MinvJt * force;
    if (!a.allFinite()) throw std::overflow_error("constrained dynamics: accelerations are not finite");
  }
};

}  // namespace freefloat::sim
