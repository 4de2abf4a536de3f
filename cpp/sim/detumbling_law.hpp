// The detumbling controller of freefloat.space.control.detumbling_control.DetumblingController in
// C++: before `start`, computed torque onto the held posture (the joint positions at the first
// period); from `start`, the detumbling solution at the measured state tracked with
//   tau = H* (qddot_d + Kd (qdot_d - qdot)) + c*,
// qddot_d the backward difference of qdot_d over the period (zero at the first detumbling period).
#pragma once

#include <optional>
#include <vector>

#include "detumbling.hpp"

namespace freefloat::sim {

struct DetumblingLaw {
  DetumblingTask task;
  double start, kp, kd, period;  // s, 1/s^2, 1/s, s
  std::optional<Vec> hold;       // held joint positions (n,), set at the first period if empty
  std::optional<Vec> previous;   // qdot_d of the previous detumbling period (n,), if any
  std::vector<double> residuals;  // max |residual| of each detumbling period, since last taken
  GeneralizedJacobian at_state;  // scratch
  Vec qdot, residual;            // scratch

  bool detumbling(double t) const { return !(t < start); }

  // Hold phase: H* (Kp (hold - q) - Kd qdot) + c*.
  Vec hold_torque(const Vec& positions, const Vec& rates, const Eigen::MatrixXd& H, const Vec& c) const {
    return H * (kp * (*hold - positions) - kd * rates) + c;
  }

  // Detumbling phase, with `at_state` filled for the measured state. Returns solve's message
  // (then tau is untouched) or an empty string.
  std::string track(const Vec& rates, const Eigen::MatrixXd& H, const Vec& c, Vec& tau) {
    std::string error = solve(at_state, task, qdot, residual);
    if (!error.empty()) return error;
    residuals.push_back(residual.size() ? residual.cwiseAbs().maxCoeff() : 0.0);
    const Vec qddot = previous ? Vec((qdot - *previous) / period) : Vec::Zero(qdot.size());
    previous = qdot;
    tau = H * (qddot + kd * (qdot - rates)) + c;
    return {};
  }
};

}  // namespace freefloat::sim
