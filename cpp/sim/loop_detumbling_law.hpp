// The two-hand detumbling law of freefloat.space.control.loop_detumbling.LoopDetumblingController
// in C++ (steps 1-4 of its docstring), each control period:
//   1. rates: the least-norm mission-joint rates stopping the task rows with the loop kept closed,
//      [J*_rows; J*_c] qdot_S = [-J0E H0^-1 M; -J_c,b M_bb^-1 p_b - beta e];
//   2. accelerations: qddot_d = (qdot_d - qdot_d^-)/T + Kd (qdot_d - qdot), projected on the
//      closure's acceleration constraint;
//   3. the closure force lambda: each hand carries half of the target's inertial wrench plus a
//      squeeze along grasp 2 -> grasp 1 (two fixed-point passes, from the previous period's lambda);
//   4. tau = H* qddot + c* - J*_c^T lambda, the largest share of qddot_d within the torque limit.
// Declarations: the definitions are in loop_detumbling_law.cpp.
#pragma once

#include <optional>
#include <vector>

#include "closures.hpp"
#include "detumbling.hpp"
#include "generalized_jacobian.hpp"
#include "simulation.hpp"

namespace freefloat::sim {

// The law of `settings` (its grasp checked by the loop) with its state so far.
struct LoopDetumblingLaw : LoopDetumblingSettings, LoopDetumblingState {
  LoopDetumblingLaw(const LoopDetumblingSettings& settings, LoopDetumblingState state)
      : LoopDetumblingSettings(settings), LoopDetumblingState(std::move(state)), closure_{settings.grasp},
        inertia_body_(settings.inertia.asDiagonal()) {}

  GeneralizedJacobian at_state;    // filled by the loop for the state before torque()

  // Joint torques (n,) at time t for (q, v); `at_state` must hold the state's generalized Jacobian.
  // M, h and the kinematics come from the plant's prepare() at (q, v), which the plant's first
  // evaluation of the period then reuses.
  void torque(const Model& m, Workspace& w, ConstrainedDynamics& plant, const Vec& q, const Vec& v, int nb, double t,
              Vec& tau);

 private:
  // Step 1 (LoopDetumblingController._rates): qdot (n,), the rows' residual logged.
  Vec rates(const Eigen::MatrixXd& Jc_star, const Vec& closure_drift);

  // Steps 2-4 for the desired joint accelerations `desired` (affine in them); lambda kept in `force`.
  Vec torques(const Vec& desired, const Vec& target_rows, const Eigen::MatrixXd& Jc_b, const Eigen::MatrixXd& to_base,
              const Eigen::MatrixXd& reaction, const Vec& bias);

  // Step 3 (LoopDetumblingController._shared_force) at the acceleration a (nv,).
  Vec6 shared_force(const Vec& a) const;

  // LoopDetumblingController._within_limit: hold + s (full - hold), the largest s in [0, 1] within
  // the limit; `hold` scaled down to it when it already exceeds it.
  Vec within_limit(const Vec& hold, const Vec& full) const;

  std::vector<ClosureSpec> closure_;  // the grasp weld, as the plant's closures
  Mat3 inertia_body_;                 // the target's inertia about its CoM, target frame axes

  // Scratch of one period.
  ClosureRows rows_;
  FrameMotion target_;
  Eigen::MatrixXd coupling_, Jc_star_, H_;
  LeastNorm projector_, rates_;  // pinv(J*_c), pinv([J*_rows; J*_c]) (rcond 1e-10), as solvers
  Vec c_;
  Mat3 hand_rotation_, inertia_world_;
  Vec3 grasp_, squeeze_axis_;
};

}  // namespace freefloat::sim
