// Loop closures on a Pinocchio tree (freefloat.dynamics.closures, the numpy reference): a closure's
// rows with exact Jacobian and drift (closure.py: frame_motion, evaluate, stacked), and the
// constrained dynamics through the Delassus matrix (constrained.py: solve, delassus_solve),
//   M a + h = tau + J^T lambda,   J a = -gamma - 2 beta J v - beta^2 e,
//   lambda = D^+ (rhs - J M^-1 (tau - h)),  D = J M^-1 J^T,
// on Pinocchio's CRBA, RNEA (with the external wrenches) and joint Jacobians (pin_plant.hpp),
// solved with Eigen: no constraint-dynamics header (they are heavy to compile), the same numbers
// as the reference. Declarations: the definitions are in closures.cpp.
#pragma once

#include <Eigen/Cholesky>

#include <vector>

#include "pin_plant.hpp"
#include "simulation.hpp"  // ClosureSpec

namespace freefloat::sim {

// closures.constrained.REDUNDANT: relative eigenvalue below which a Delassus direction carries no force.
constexpr double kRedundant = 1e-12;

// The closures' rows stacked (closure.stacked): residual e (m,), Jacobian J (m, nv) and, when
// `drift`, gamma (m,), at the state ConstrainedDynamics::prepare() left in `w`.
struct ClosureRows {
  Vec e, gamma;
  Eigen::MatrixXd J;
  FrameMotion one, two;  // scratch

  void evaluate(const std::vector<ClosureSpec>& closures, const Model& m, Workspace& w, bool drift);
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
  std::vector<ClosureSpec> closures;  // checked by the loop (Loop::check_closure)
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

  // M (symmetric), h = RNEA(q, v, 0) (with the wrenches set_wrenches() left in `w` when
  // `with_wrenches`), the closures' rows, the Cholesky factor of M, M^-1 J^T and D at (q, v), `w`
  // left with what frame_motion reads; kept for solve() without wrenches. Throws
  // std::overflow_error when M is not positive definite.
  void prepare(const Model& m, Workspace& w, const Vec& q, const Vec& v, bool with_wrenches = false);

  // The accelerations `a` at (q, v) under generalized forces tau (nv,), with the wrenches of `w`
  // when `with_wrenches`. Throws std::overflow_error with the reference's message when M is not
  // positive definite or `a` is not finite.
  void solve(const Model& m, Workspace& w, const Vec& q, const Vec& v, const Vec& tau, bool with_wrenches, Vec& a);
};

}  // namespace freefloat::sim
