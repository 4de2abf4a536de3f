// Loop closures on a Pinocchio tree (freefloat.dynamics.closures, the numpy reference): a closure's
// rows with exact Jacobian and drift (closure.py: frame_motion, evaluate, stacked), and the
// constrained dynamics through the Delassus matrix (constrained.py: solve, delassus_solve),
//   M a + h = tau + J^T lambda,   J a = -gamma - 2 beta J v - beta^2 e,
//   lambda = D^+ (rhs - J M^-1 (tau - h)),  D = J M^-1 J^T,
// on Pinocchio's CRBA, RNEA (with the external wrenches) and joint Jacobians, solved with Eigen:
// no constraint-dynamics header (they are heavy to compile), the same numbers as the reference.
// Declarations: the definitions are in cpp/closures.cpp, a translation unit of its own that
// compiles beside cpp/sim_module.cpp (the Eigen kernels they need doubled that unit's time).
#pragma once

#include <Eigen/Cholesky>

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
void frame_motion(const Model& m, Data& d, JointIndex joint, const SE3& placement, FrameMotion& out);

// The closures' rows stacked (closure.stacked): residual e (m,), Jacobian J (m, nv) and, when
// `drift`, gamma (m,), at the state kinematics() left in `d`.
struct ClosureRows {
  Vec e, gamma;
  Eigen::MatrixXd J;
  FrameMotion one, two;  // scratch

  void evaluate(const std::vector<Closure>& closures, const Model& m, Data& d, bool drift);
};

// constrained.delassus_solve: D^+ rhs for a symmetric positive semi-definite D, and its rank.
// Cholesky when D is surely well conditioned (1 / trace(D^-1) > kRedundant trace(D)), otherwise
// the pseudo-inverse whose directions under kRedundant times the largest eigenvalue carry no force
// (for such a D its singular values are its eigenvalues: the SVD of pinv() gives
// numpy.linalg.eigh's cut, and no eigensolver is compiled).
int delassus_solve(const Eigen::MatrixXd& D, const Vec& rhs, Vec& out);

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
  Eigen::LLT<Eigen::MatrixXd> llt;
  Vec h, zero, a_free, rhs;
  Vec state_q, state_v;  // the state M, h, rows, ... are for, when `kept`
  bool kept = false;

  bool empty() const { return closures.empty(); }
  // Forget the kept state (the model's numbers or the closures changed).
  void forget() { kept = false; }

  // M (symmetric), h = RNEA(q, v, 0, fext), the closures' rows, the Cholesky factor of M, M^-1 J^T
  // and D at (q, v), `d` left with what frame_motion reads; kept for solve() when `fext` is null.
  // Throws std::overflow_error when M is not positive definite.
  void prepare(const Model& m, Data& d, const Vec& q, const Vec& v,
               const std::vector<pinocchio::Force>* fext = nullptr);

  // The accelerations `a` at (q, v) under generalized forces tau (nv,) and the external wrenches
  // `fext` (one per joint, joint frames; null: none). Throws std::overflow_error with the
  // reference's message when M is not positive definite or `a` is not finite.
  void solve(const Model& m, Data& d, const Vec& q, const Vec& v, const Vec& tau,
             const std::vector<pinocchio::Force>* fext, Vec& a);
};

}  // namespace freefloat::sim
