// The definitions of loop_detumbling_law.hpp: the two-hand detumbling law, on the closed plant of
// closures.hpp and pin_plant.hpp's Pinocchio calls.
#include <algorithm>
#include <cmath>

#include "loop_detumbling_law.hpp"

namespace freefloat::sim {

void LoopDetumblingLaw::torque(const Model& m, Workspace& w, ConstrainedDynamics& plant, const Vec& q, const Vec& v, int nb,
                               double t, Vec& tau) {
  const int n = nv(m) - nb, mc = closure_[0].size();
  plant.prepare(m, w, q, v);
  const Eigen::MatrixXd& M = plant.M;
  const Vec& h = plant.h;  // RNEA(q, v, 0): the nonlinear effects
  rows_.evaluate(closure_, m, w, true);
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
  frame_motion(m, w, target_joint, target_placement, target_);
  hand_rotation_ = frame_pose(w, closure_[0].joint1, closure_[0].placement1).rotation;
  grasp_ = frame_pose(w, closure_[0].joint2, closure_[0].placement2).position;
  const Vec3 other = frame_pose(w, first_joint, first_placement).position;
  squeeze_axis_ = (other - grasp_) / std::max((other - grasp_).norm(), 1e-12);
  const Mat3& R = target_.rotation;
  inertia_world_ = R * inertia_body_ * R.transpose();
  const Vec target = -rows_.gamma - 2.0 * baumgarte * (Jc * v) - baumgarte * baumgarte * rows_.e;
  tau = torques(qddot_d, target, Jc.leftCols(nb), to_base, reaction, bias);
  const bool saturates = limit > 0.0 && tau.cwiseAbs().maxCoeff() > limit;
  if (saturates) tau = within_limit(torques(Vec::Zero(n), target, Jc.leftCols(nb), to_base, reaction, bias), tau);
  times.push_back(t);
  saturated.push_back(saturates);
}

Vec LoopDetumblingLaw::rates(const Eigen::MatrixXd& Jc_star, const Vec& closure_drift) {
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

Vec LoopDetumblingLaw::torques(const Vec& desired, const Vec& target_rows, const Eigen::MatrixXd& Jc_b,
                                const Eigen::MatrixXd& to_base, const Eigen::MatrixXd& reaction, const Vec& bias) {
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

Vec6 LoopDetumblingLaw::shared_force(const Vec& a) const {
  const Vec3& w = target_.angular_velocity;
  const Vec3 linear = mass * (target_.jacobian.topRows<3>() * a + target_.acceleration);
  const Vec3 angular = inertia_world_ * (target_.jacobian.bottomRows<3>() * a + target_.angular_acceleration) +
                       w.cross(inertia_world_ * w);
  const Vec3 f = 0.5 * linear + squeeze * squeeze_axis_;
  const Vec3 n_grasp = 0.5 * angular - (grasp_ - target_.position).cross(f);
  Vec6 out;
  out << hand_rotation_.transpose() * f, hand_rotation_.transpose() * n_grasp;
  return out;
}

Vec LoopDetumblingLaw::within_limit(const Vec& hold, const Vec& full) const {
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

}  // namespace freefloat::sim
