// The two-hand detumbling law of freefloat.space.control.loop_detumbling.LoopDetumblingController
// in C++ (steps 1-4 of its docstring), each control period:
//   1. rates: the least-norm mission-joint rates stopping the task rows with the loop kept closed,
//      [J*_rows; J*_c] qdot_S = [-J0E H0^-1 M; -J_c,b M_bb^-1 p_b - beta e];
//   2. accelerations: qddot_d = (qdot_d - qdot_d^-)/T + Kd (qdot_d - qdot), projected on the
//      closure's acceleration constraint;
//   3. the closure force lambda: each hand carries half of the target's inertial wrench plus a
//      squeeze along grasp 2 -> grasp 1 (two fixed-point passes, from the previous period's lambda);
//   4. tau = H* qddot + c* - J*_c^T lambda, the largest share of qddot_d within the torque limit.
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
              Vec& tau) {
    const int n = m.nv - nb, mc = closure[0].size();
    plant.prepare(m, d, q, v);
    const Eigen::MatrixXd& M = plant.M;
    const Vec& h = plant.h;  // RNEA(q, v, 0): the nonlinear effects
    rows_.evaluate(closure, m, d, true);
    const Eigen::MatrixXd& Jc = rows_.J;
    Eigen::MatrixXd rhs(nb, n + 2 + mc);
    rhs.leftCols(n) = M.topRightCorner(nb, n);
    rhs.col(n) = M.topRows(nb) * v;
    rhs.col(n + 1) = h.head(nb);
    rhs.rightCols(mc) = Jc.leftCols(nb).transpose();
    coupling_ = M.topLeftCorner(nb, nb).partialPivLu().solve(rhs);
    const auto to_base = coupling_.leftCols(n), reaction = coupling_.rightCols(mc);
    const Vec momentum = coupling_.col(n), bias = coupling_.col(n + 1);
    Jc_star_ = Jc.rightCols(n) - Jc.leftCols(nb) * to_base;
    const Vec qdot_d = rates(Jc_star_, Jc.leftCols(nb) * momentum + baumgarte * rows_.e);
    Vec qddot_d = kd * (qdot_d - v.tail(n));
    if (previous) qddot_d += (qdot_d - *previous) / period;
    previous = qdot_d;
    projector_.compute(Jc_star_, 1e-10);
    H_ = M.bottomRightCorner(n, n) - M.topRightCorner(nb, n).transpose() * to_base;
    c_ = h.tail(n) - M.topRightCorner(nb, n).transpose() * bias;
    frame_motion(m, d, target_joint, target_placement, target_);
    const SE3 hand = d.oMi[closure[0].joint1] * closure[0].placement1;
    hand_rotation_ = hand.rotation();
    grasp_ = (d.oMi[closure[0].joint2] * closure[0].placement2).translation();
    const Vec3 other = (d.oMi[first_joint] * first_placement).translation();
    squeeze_axis_ = (other - grasp_) / std::max((other - grasp_).norm(), 1e-12);
    const Mat3& R = target_.pose.rotation();
    inertia_world_ = R * inertia * R.transpose();
    const Vec target = -rows_.gamma - 2.0 * baumgarte * (Jc * v) - baumgarte * baumgarte * rows_.e;
    tau = torques(qddot_d, target, Jc.leftCols(nb), to_base, reaction, bias);
    const bool saturates = limit > 0.0 && tau.cwiseAbs().maxCoeff() > limit;
    if (saturates) tau = within_limit(torques(Vec::Zero(n), target, Jc.leftCols(nb), to_base, reaction, bias), tau);
    times.push_back(t);
    saturated.push_back(saturates);
  }

 private:
  // Step 1 (LoopDetumblingController._rates): qdot (n,), the rows' residual logged.
  Vec rates(const Eigen::MatrixXd& Jc_star, const Vec& closure_drift) {
    const GeneralizedJacobian& g = at_state;
    const int r = static_cast<int>(rows.size()), s = static_cast<int>(joints.size()), mc = Jc_star.rows();
    Eigen::MatrixXd A(r + mc, s);
    Vec b(r + mc);
    for (int i = 0; i < r; ++i) {
      b[i] = -g.drift[rows[i]];
      for (int j = 0; j < s; ++j) A(i, j) = g.Jstar(rows[i], joints[j]);
    }
    for (int i = 0; i < mc; ++i) {
      b[r + i] = -closure_drift[i];
      for (int j = 0; j < s; ++j) A(r + i, j) = Jc_star(i, joints[j]);
    }
    rates_.compute(A, 1e-10);
    const Vec qS = rates_.solve(b);
    Vec qdot = Vec::Zero(g.Jstar.cols());
    for (int j = 0; j < s; ++j) qdot[joints[j]] = qS[j];
    double largest = 0.0;
    for (int i = 0; i < r; ++i) largest = std::max(largest, std::abs(g.Jstar.row(rows[i]).dot(qdot) + g.drift[rows[i]]));
    residuals.push_back(largest);
    return qdot;
  }

  // Steps 2-4 for the desired joint accelerations `desired` (affine in them); lambda kept in `force`.
  template <typename Jcb, typename ToBase, typename Reaction>
  Vec torques(const Vec& desired, const Vec& target_rows, const Jcb& Jc_b, const ToBase& to_base,
              const Reaction& reaction, const Vec& bias) {
    Vec qddot, a(to_base.rows() + to_base.cols());
    Vec6 lambda = force;
    for (int pass = 0; pass < 2; ++pass) {  // lambda moves the base only through J_c,b
      const Vec target = target_rows + Jc_b * (bias - reaction * lambda);
      qddot = desired - projector_.solve(Jc_star_ * desired - target);
      a.head(to_base.rows()) = reaction * lambda - to_base * qddot - bias;
      a.tail(qddot.size()) = qddot;
      lambda = shared_force(a);
    }
    force = lambda;
    return H_ * qddot + c_ - Jc_star_.transpose() * lambda;
  }

  // Step 3 (LoopDetumblingController._shared_force) at the acceleration a (nv,).
  Vec6 shared_force(const Vec& a) const {
    const Vec3& w = target_.angular_velocity;
    const Vec3 linear = mass * (target_.jacobian.topRows<3>() * a + target_.acceleration);
    const Vec3 angular = inertia_world_ * (target_.jacobian.bottomRows<3>() * a + target_.angular_acceleration) +
                         w.cross(inertia_world_ * w);
    const Vec3 f = 0.5 * linear + squeeze * squeeze_axis_;
    const Vec3 n_grasp = 0.5 * angular - (grasp_ - target_.pose.translation()).cross(f);
    Vec6 out;
    out << hand_rotation_.transpose() * f, hand_rotation_.transpose() * n_grasp;
    return out;
  }

  // LoopDetumblingController._within_limit: hold + s (full - hold), the largest s in [0, 1] within
  // the limit; `hold` scaled down to it when it already exceeds it.
  Vec within_limit(const Vec& hold, const Vec& full) const {
    const double peak = hold.cwiseAbs().maxCoeff();
    if (peak >= limit) return hold * (limit / peak);
    const Vec step = full - hold;
    double room = 1.0;
    for (int i = 0; i < step.size(); ++i) {
      if (step[i] > 0) room = std::min(room, (limit - hold[i]) / step[i]);
      else if (step[i] < 0) room = std::min(room, (-limit - hold[i]) / step[i]);
    }
    return hold + room * step;
  }

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
