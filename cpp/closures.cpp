// The definitions of closures.hpp (the constrained dynamics of a tree with loop closures) and of
// loop_detumbling_law.hpp (the two-hand detumbling law), compiled in sim_unit.cpp's translation
// unit; their Pinocchio calls are pin_plant.hpp's.
#include <algorithm>
#include <stdexcept>

#include "sim/closures.hpp"
#include "sim/detumbling.hpp"  // pinv, LeastNorm
#include "sim/loop_detumbling_law.hpp"

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
