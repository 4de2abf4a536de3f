// The two-hand detumbling law of freefloat.space.control.loop_detumbling.LoopDetumblingController
// in C++ (steps 1-4 of its docstring), each control period:
//   1. rates: the least-norm mission-joint rates stopping the task rows with the loop kept closed,
//      [J*_rows; J*_c] qdot_S = [-J0E H0^-1 M; -J_c,b M_bb^-1 p_b - beta e];
//   2. accelerations: qddot_d = (qdot_d - qdot_d^-)/T + Kd (qdot_d - qdot), projected on the
//      closure's acceleration constraint;
//   3. the closure force lambda: each hand carries half of the target's inertial wrench plus a
//      squeeze along grasp 2 -> grasp 1 (two fixed-point passes, from the previous period's lambda);
//   4. tau = H* qddot + c* - J*_c^T lambda, the largest share of qddot_d within the torque limit.
// Declarations: the definitions are in cpp/closures.cpp (see closures.hpp).
#pragma once

#include <optional>
#include <vector>

#include "closures.hpp"
#include "detumbling.hpp"

namespace freefloat::sim {

struct LoopDetumblingLaw {
  std::vector<int> rows, joints;  // task rows into the 6k rows [v_E; w_E]; mission joints
  double kd = 0.0, period = 0.0, baumgarte = 0.0, squeeze = 0.0, limit = 0.0;  // 1/s, s, 1/s, N, N m (0: none)
  std::vector<Closure> closure;   // the weld between the second hand (frame 1) and its grasp on the target
  JointIndex target_joint = 0, first_joint = 0;
  SE3 target_placement = SE3::Identity(), first_placement = SE3::Identity();  // target CoM frame, first hand
  double mass = 0.0;               // kg
  Mat3 inertia = Mat3::Zero();     // principal moments, target frame axes
  // State carried from period to period (handed back to Python after each chunk).
  std::optional<Vec> previous;     // qdot_d of the previous period (n,)
  Vec6 force = Vec6::Zero();       // lambda of the previous period
  std::vector<double> times, residuals;  // LoopLog.t, LoopLog.rows_residual since last taken
  std::vector<bool> saturated;           // LoopLog.saturated
  GeneralizedJacobian at_state;    // filled by the loop for the state before torque()

  // Joint torques (n,) at time t for (q, v); `at_state` must hold the state's generalized Jacobian.
  // M, h and the kinematics come from the plant's prepare() at (q, v), which the plant's first
  // evaluation of the period then reuses.
  void torque(const Model& m, Data& d, ConstrainedDynamics& plant, const Vec& q, const Vec& v, int nb, double t,
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
