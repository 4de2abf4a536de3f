// The numerics of mechanism.hpp's closed chains at one point: the serial chains' kinematics and
// dynamics, Mechanism's closure and dynamics terms, the passive LU, C and the forward dynamics
// (eq 129): the closed-chain loop's plant and its law's model (sim/chain_loop.cpp). The inverse
// dynamics and the assembly are a unit of their own (inverse.cpp): the two in one unit took 0.98 GB
// of compiler memory (g++ 12, -O3).
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "mechanism.hpp"

namespace freefloat {

namespace {

// SerialChain.frames and tip_jacobians.
void chain_frames(const Chain& c, const double* q, ChainState& s) {
  s.H.resize(c.nu + 1);
  s.k.resize(c.nu);
  s.o.resize(c.nu);
  s.H[0] = c.base;
  Mat4 J = c.base * c.placement[0];
  for (int i = 0; i < c.nu; ++i) {
    s.k[i] = J.block<3, 1>(0, 2);
    s.o[i] = J.block<3, 1>(0, 3);
    Mat4 moved = J;
    if (c.prismatic[i]) {
      moved.block<3, 1>(0, 3) += J.block<3, 1>(0, 2) * q[i];
    } else {
      const double co = std::cos(q[i]), si = std::sin(q[i]);
      moved.col(0) = J.col(0) * co + J.col(1) * si;
      moved.col(1) = J.col(1) * co - J.col(0) * si;
    }
    s.H[i + 1] = moved * c.link[i];
    if (i + 1 < c.nu) J = moved * c.link_next[i];
  }
  const Mat4& last = s.H[c.nu];
  s.R_tip = last.topLeftCorner<3, 3>();
  s.x = s.R_tip * c.tip_point + last.block<3, 1>(0, 3);
  s.tip_Jv.resize(3, c.nu);
  s.tip_Jw.setZero(3, c.nu);
  for (int j = 0; j < c.nu; ++j) {
    if (c.prismatic[j]) {
      s.tip_Jv.col(j) = s.k[j];
    } else {
      s.tip_Jv.col(j) = s.k[j].cross(s.x - s.o[j]);
      s.tip_Jw.col(j) = s.k[j];
    }
  }
}

// SerialChain.kinematics and dynamics_from at qd, after chain_frames at q.
void chain_dynamics(const Chain& c, const double* qd, ChainState& s) {
  const int n = c.nu;
  std::vector<V3> k_rev(n), w_N(n), w_prev(n), dw0_N(n);
  V3 w = V3::Zero(), dw = V3::Zero();
  for (int j = 0; j < n; ++j) {
    k_rev[j] = c.prismatic[j] ? V3::Zero() : s.k[j];
    w_prev[j] = w;
    w += k_rev[j] * qd[j];
    w_N[j] = w;
    dw += w_prev[j].cross(k_rev[j]) * qd[j];
    dw0_N[j] = dw;
  }
  // eq 50: sum_j k x (k x (p - o_j)) qd_j^2 + 2 w_{j-1} x jv_j qd_j over the joints j < count
  auto bias = [&](const V3& p, const DMat& jac, int count) {
    V3 out = V3::Zero();
    for (int j = 0; j < count; ++j)
      out += k_rev[j].cross(k_rev[j].cross(p - s.o[j])) * (qd[j] * qd[j]) + 2.0 * w_prev[j].cross(V3(jac.col(j))) * qd[j];
    return out;
  };
  s.M.setZero(n, n);
  s.v.setZero(n);
  s.g.setZero(n);
  DMat Jv(3, n), Jw_N(3, n);
  for (int i = 0; i < n; ++i) {
    const M3 R = s.H[i + 1].topLeftCorner<3, 3>();
    const V3 gi = R * c.com[i] + s.H[i + 1].block<3, 1>(0, 3);
    Jv.setZero();
    Jw_N.setZero();
    for (int j = 0; j <= i; ++j) {
      Jv.col(j) = c.prismatic[j] ? s.k[j] : V3(s.k[j].cross(gi - s.o[j]));
      Jw_N.col(j) = k_rev[j];
    }
    const DMat Jw = R.transpose() * Jw_N;
    const V3 ci = bias(gi, Jv, i + 1);
    const V3 dw0 = R.transpose() * dw0_N[i];
    const V3 wi = R.transpose() * w_N[i];
    const M3& I = c.inertia[i];
    s.M += c.mass[i] * Jv.transpose() * Jv + Jw.transpose() * I * Jw;
    const V3 torque = I * dw0 + wi.cross(I * wi);
    s.v += Jv.transpose() * (c.mass[i] * ci) + Jw.transpose() * torque;
    s.g -= c.mass[i] * (Jv.transpose() * c.gravity);
  }
  s.M = 0.5 * (s.M + s.M.transpose()).eval();
  s.tip_c = bias(s.x, s.tip_Jv, n);
  s.tip_dw = dw0_N[n - 1];
}

// mechanism.log3: rotation vector for angles below pi, a series below 1e-6 rad.
V3 log3(const M3& R) {
  const V3 vee = 0.5 * V3(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  const double sin = vee.norm();
  const double angle = std::atan2(sin, 0.5 * (R.trace() - 1.0));
  const double scale = angle < 1e-6 ? 1.0 + angle * angle / 6.0 : angle / sin;
  return scale * vee;
}

}  // namespace

void Mechanism::closure(const double* q, DVec& residual, DMat& A) {
  if (closure_q.size() == n_q && std::equal(q, q + n_q, closure_q.data())) {
    residual = closure_residual;
    A = closure_A;
    return;
  }
  evaluate_closure(q, residual, A);
  closure_q = Eigen::Map<const DVec>(q, n_q);
  closure_residual = residual;
  closure_A = A;
}

void Mechanism::evaluate_closure(const double* q, DVec& residual, DMat& A) {
  states.resize(chains.size());
  const int nc = static_cast<int>(chains.size());
  DVec& x = x_buf;
  DVec& phi = phi_buf;
  DMat& Jv = Jv_buf;
  DMat& Jw = Jw_buf;
  x.resize(3 * nc);
  phi.resize(3 * nc);
  Jv.setZero(3 * nc, n_q - p);
  Jw.setZero(3 * nc, n_q - p);
  int col = 0;
  for (int c = 0; c < nc; ++c) {
    chain_frames(chains[c], q + p + col, states[c]);
    x.segment<3>(3 * c) = states[c].x;
    Jv.block(3 * c, col, 3, chains[c].nu) = states[c].tip_Jv;
    Jw.block(3 * c, col, 3, chains[c].nu) = states[c].tip_Jw;
    if (angular) phi.segment<3>(3 * c) = log3(states[c].R_tip * reference[c].transpose());
    col += chains[c].nu;
  }
  const Eigen::Map<const DVec> qs(q, p), qo(q + p, n_q - p);
  residual.resize(m());
  A.resize(m(), n_q);
  residual.head(m_lin) = D * qs - d - E * x - F * qo;
  A.topLeftCorner(m_lin, p) = D;
  A.topRightCorner(m_lin, n_q - p) = -(E * Jv + F);
  if (angular) {
    residual.tail(m_ang) = offset - Q * phi - R * qo;
    A.bottomLeftCorner(m_ang, p) = P;
    A.bottomRightCorner(m_ang, n_q - p) = -(Q * Jw + R);
  }
}

void Mechanism::dynamics(const double* qd, DVec& b, DMat& M, DVec& v, DVec& g) {
  const int nc = static_cast<int>(chains.size());
  DVec& tip_c = tip_c_buf;
  DVec& tip_dw = tip_dw_buf;
  tip_c.resize(3 * nc);
  tip_dw.resize(3 * nc);
  M.setZero(n_q, n_q);
  v.setZero(n_q);
  g.resize(n_q);
  M.topLeftCorner(p, p) = platform_mass;
  g.head(p) = platform_gravity;
  int col = p;
  for (int c = 0; c < nc; ++c) {
    chain_dynamics(chains[c], qd + col, states[c]);
    tip_c.segment<3>(3 * c) = states[c].tip_c;
    tip_dw.segment<3>(3 * c) = states[c].tip_dw;
    const int nu = chains[c].nu;
    M.block(col, col, nu, nu) = states[c].M;
    v.segment(col, nu) = states[c].v;
    g.segment(col, nu) = states[c].g;
    col += nu;
  }
  b.resize(m());
  b.head(m_lin) = E * tip_c;
  if (angular) b.tail(m_ang) = Q * tip_dw;
}

Eigen::PartialPivLU<DMat> Mechanism::passive_lu(const DMat& A) const {
  Eigen::PartialPivLU<DMat> lu(A.rightCols(n_q - p));
  const auto diag = lu.matrixLU().diagonal();
  for (int i = 0; i < diag.size(); ++i)
    if (diag[i] == 0.0 || !std::isfinite(diag[i]))
      throw MechanismError("the passive joints' constraint Jacobian A° is singular: the mechanism is at a singular pose "
                           "(C and the inverse dynamics are undefined there)");
  return lu;
}

DMat Mechanism::velocity_map(const DMat& A, const Eigen::PartialPivLU<DMat>& lu) const {
  DMat C(n_q, p);
  C.topRows(p).setIdentity();
  C.bottomRows(n_q - p) = -lu.solve(A.leftCols(p));
  return C;
}

DMat Mechanism::velocity_map(const DMat& A) const { return velocity_map(A, passive_lu(A)); }

DVec Mechanism::forward(const double* q, const double* qd, const double* tau, double baumgarte) {
  DVec residual, b, v, g;
  DMat A, M;
  closure(q, residual, A);
  dynamics(qd, b, M, v, g);
  const DVec vg = v + g;
  const DMat C = velocity_map(A);
  const DVec u = U * Eigen::Map<const DVec>(tau, U.cols());
  DVec rates = A * Eigen::Map<const DVec>(qd, n_q);
  rates.head(m_lin) *= 2.0;
  DVec rhs_c = b - baumgarte * rates;
  rhs_c.head(m_lin) -= baumgarte * baumgarte * residual.head(m_lin);
  DMat lhs(n_q, n_q);
  lhs << C.transpose() * M, A;
  DVec rhs(n_q);
  rhs << C.transpose() * (u - vg), rhs_c;
  return lhs.partialPivLu().solve(rhs);
}

}  // namespace freefloat
