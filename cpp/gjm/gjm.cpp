// The definitions of gjm.hpp: body kinematics, composite inertias, H0, H0m, Hm, H*, the
// end-effector Jacobians and the joint and time derivatives. A translation unit of its own, without
// pybind11 (bindings/core.cpp binds them), so that no unit compiles the bindings and the numerics
// together.
#include "gjm.hpp"

#include <cmath>
#include <vector>

namespace freefloat {

// The helpers of this unit stay `inline`: g++ -O3 weighs the keyword, and without it derivatives()
// called cross_motion, cross_force and inertia_rate out of line (1 us, 15 %, slower a call).
namespace {

// s x x for motion vectors [v; w].
inline Vec6 cross_motion(const Vec6& s, const Vec6& x) {
  Vec6 out;
  out.head<3>() = s.tail<3>().cross(x.head<3>()) + s.head<3>().cross(x.tail<3>());
  out.tail<3>() = s.tail<3>().cross(x.tail<3>());
  return out;
}

// s x* f for force vectors [f; n] (= -crm(s)^T f).
inline Vec6 cross_force(const Vec6& s, const Vec6& f) {
  Vec6 out;
  out.head<3>() = s.tail<3>().cross(f.head<3>());
  out.tail<3>() = s.tail<3>().cross(f.tail<3>()) + s.head<3>().cross(f.head<3>());
  return out;
}

// Rate of an inertia carried by the motion s: s x* I - I s x.
inline Mat6 inertia_rate(const Vec6& s, const Mat6& I) {
  Mat6 crm = Mat6::Zero();
  crm.topLeftCorner<3, 3>() = skew(s.tail<3>());
  crm.topRightCorner<3, 3>() = skew(s.head<3>());
  crm.bottomRightCorner<3, 3>() = crm.topLeftCorner<3, 3>();
  const Mat6 IC = I * crm;
  return -(IC.transpose() + IC);
}

// Body poses: joint motions (Rodrigues or a slide) composed from the base outwards.
inline void forward_kinematics(const Tree& t, const double* q, const Mat3& Rb, const Vec3& pb, Kinematics& kin) {
  const int nb = t.bodies();
  kin.rotation.resize(nb);
  kin.origin.resize(nb);
  kin.com.resize(nb);
  kin.inertia.resize(nb);
  kin.joint_axis.resize(t.n);
  kin.rotation[0] = Rb;
  kin.origin[0] = pb;
  for (int j = 0; j < t.n; ++j) {
    const int b = j + 1, a = t.parent[j];
    const int iq = t.q_index[j];
    const double theta = t.circle[j] ? std::atan2(q[iq + 1], q[iq]) : q[iq];
    Mat3 motion = Mat3::Identity();
    Vec3 slide = Vec3::Zero();
    if (t.revolute[j]) {
      const Mat3 K = skew(t.axis[j]);
      motion += std::sin(theta) * K + (1.0 - std::cos(theta)) * (K * K);
    } else {
      slide = t.axis[j] * theta;
    }
    kin.rotation[b] = kin.rotation[a] * (t.place_R[j] * motion);
    kin.origin[b] = kin.origin[a] + kin.rotation[a] * (t.place_R[j] * slide + t.place_t[j]);
    kin.joint_axis[j] = kin.rotation[b] * t.axis[j];
  }
  for (int b = 0; b < nb; ++b) {
    kin.com[b] = kin.origin[b] + kin.rotation[b] * t.com[b];
    kin.inertia[b] = kin.rotation[b] * t.inertia[b] * kin.rotation[b].transpose();
  }
  kin.r0 = pb + Rb * t.base_com;
  kin.R0 = Rb * t.base_com_rotation;
}

// Spatial inertia about r0 of a body of mass m, CoM offset c = r_b - r0 and inertia Icom.
inline Mat6 spatial_inertia(double m, const Vec3& c, const Mat3& Icom) {
  const Mat3 C = skew(c);
  Mat6 I;
  I.topLeftCorner<3, 3>() = m * Mat3::Identity();
  I.topRightCorner<3, 3>() = -m * C;
  I.bottomLeftCorner<3, 3>() = m * C;
  I.bottomRightCorner<3, 3>() = Icom - m * C * C;
  return I;
}

}  // namespace

void base_state(const Tree& t, const double* q, const double* v, Mat3& R, Vec3& p, Vec6& x0dot) {
  Vec3 lin, ang;
  if (t.free_base) {
    p = Vec3(q[0], q[1], q[2]);
    R = Eigen::Quaterniond(q[6], q[3], q[4], q[5]).toRotationMatrix();
    lin = Vec3(v[0], v[1], v[2]);
    ang = Vec3(v[3], v[4], v[5]);
  } else {
    p = Vec3(q[0], q[1], 0.0);
    R << q[2], -q[3], 0.0, q[3], q[2], 0.0, 0.0, 0.0, 1.0;
    lin = Vec3(v[0], v[1], 0.0);
    ang = Vec3(0.0, 0.0, v[2]);
  }
  x0dot.head<3>() = R * (lin + ang.cross(t.base_com));
  x0dot.tail<3>() = R * ang;
}

void compute_inertia(const Tree& t, const double* q, const double* v, State& s) {
  const int n = t.n, nb = t.bodies();
  const int n_base = t.free_base ? 6 : 3;
  Mat3 Rb;
  Vec3 pb;
  base_state(t, q, v, Rb, pb, s.x0dot);
  Kinematics& kin = s.kin;
  forward_kinematics(t, q, Rb, pb, kin);
  const Vec3 r0 = kin.r0;

  s.S.resize(n);
  for (int j = 0; j < n; ++j) {
    const Vec3& a = kin.joint_axis[j];
    if (t.revolute[j]) s.S[j] << a.cross(r0 - kin.origin[j + 1]), a;
    else s.S[j] << a, Vec3::Zero();
  }
  s.Ic.resize(nb);
  for (int b = 0; b < nb; ++b) s.Ic[b] = spatial_inertia(t.mass[b], kin.com[b] - r0, kin.inertia[b]);
  for (int b = nb - 1; b >= 1; --b) s.Ic[t.parent[b - 1]] += s.Ic[b];

  s.H0 = s.Ic[0];
  s.H0m.resize(6, n);
  for (int j = 0; j < n; ++j) s.H0m.col(j) = s.Ic[j + 1] * s.S[j];
  s.H0_ldlt.compute(s.H0);
  s.H0_inv = s.H0_ldlt.solve(Mat6::Identity());
  s.qdot = Eigen::Map<const VecX>(v + n_base, n);
  s.momentum_base = s.H0 * s.x0dot + s.H0m * s.qdot;
  s.momentum_origin = s.momentum_base;
  s.momentum_origin.tail<3>() += r0.cross(s.momentum_base.head<3>());
}

Mat6X solve0(const State& s, const Mat6X& X) {
  Mat6X out(6, X.cols());
  for (Eigen::Index j = 0; j < X.cols(); ++j) out.col(j).noalias() = s.H0_inv * X.col(j);
  return out;
}

void compute_generalized_inertia(const Tree& t, State& s) {
  const int n = t.n;
  s.Hm.setZero(n, n);
  for (int j = 0; j < n; ++j) {
    s.Hm(j, j) = s.S[j].dot(s.H0m.col(j));
    for (int i : t.above[j]) s.Hm(i, j) = s.Hm(j, i) = s.S[i].dot(s.H0m.col(j));
  }
  s.J0 = -solve0(s, s.H0m);  // (6, n), row-major: its rows are what H* and J* combine
  s.Hstar.resize(n, n);
  for (int i = 0; i < n; ++i) {
    s.Hstar.row(i).tail(n - i) = s.Hm.row(i).tail(n - i) + s.H0m.col(i).transpose() * s.J0.rightCols(n - i);
    for (int j = i + 1; j < n; ++j) s.Hstar(j, i) = s.Hstar(i, j);
  }
}

void compute_jacobians(const Tree& t, State& s) {
  const int n = t.n, k = static_cast<int>(t.ee_body.size());
  const Kinematics& kin = s.kin;
  const Vec3 r0 = kin.r0;
  s.ee_position.resize(k, 3);
  s.Jm.setZero(6 * k, n);
  s.J0E.setZero(6 * k, 6);
  s.Jstar.resize(6 * k, n);
  for (int e = 0; e < k; ++e) {
    const int b = t.ee_body[e];
    const Vec3 rE = kin.origin[b] + kin.rotation[b] * t.ee_offset[e];
    s.ee_position.row(e) = rE.transpose();
    if (b > 0) {
      const auto column = [&](int j) {
        const Vec3& a = kin.joint_axis[j];
        if (t.revolute[j]) {
          s.Jm.block<3, 1>(6 * e, j) = a.cross(rE - kin.origin[j + 1]);
          s.Jm.block<3, 1>(6 * e + 3, j) = a;
        } else {
          s.Jm.block<3, 1>(6 * e, j) = a;
        }
      };
      column(b - 1);
      for (int j : t.above[b - 1]) column(j);
    }
    const Mat3 lever = skew(rE - r0);
    s.J0E.block<6, 6>(6 * e, 0).setIdentity();
    s.J0E.block<3, 3>(6 * e, 3) = -lever;
    s.Jstar.middleRows<3>(6 * e) = s.Jm.middleRows<3>(6 * e) + s.J0.topRows<3>() - lever * s.J0.bottomRows<3>();
    s.Jstar.middleRows<3>(6 * e + 3) = s.Jm.middleRows<3>(6 * e + 3) + s.J0.bottomRows<3>();
  }
}

void compute(const Tree& t, const double* q, const double* v, State& s) {
  compute_inertia(t, q, v, s);
  compute_generalized_inertia(t, s);
  compute_jacobians(t, s);
}

void derivatives(const Tree& t, const State& s, Derivatives& d) {
  const int n = t.n;
  d.dH0.resize(static_cast<size_t>(n) * 36);
  d.dH0m_columns.resize(n);
  d.dHm_entries.resize(n);
  // Joint k moves the joints it carries rigidly; it changes only the entries that pair a joint
  // strictly above it with a joint it carries or with another joint above it.
  std::vector<Vec6> SxSk(n), IcS(n);  // S_i x S_k and Ic_{k+1} S_i for the joints i above k
  for (int k = 0; k < n; ++k) {
    const Vec6& Sk = s.S[k];
    const Mat6& Ick = s.Ic[k + 1];
    Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> dH0(d.dH0.data() + 36 * k);
    dH0 = inertia_rate(Sk, Ick);
    auto& columns = d.dH0m_columns[k];
    auto& entries = d.dHm_entries[k];
    columns.clear();
    entries.clear();
    for (int j : t.carried[k]) columns.push_back({j, cross_force(Sk, s.H0m.col(j))});
    for (int i : t.above[k]) {
      SxSk[i] = cross_motion(s.S[i], Sk);
      IcS[i] = Ick * s.S[i];
      columns.push_back({i, cross_force(Sk, IcS[i]) - Ick * cross_motion(Sk, s.S[i])});
    }
    for (int i : t.above[k]) {
      for (int j : t.carried[k]) entries.push_back({i, j, SxSk[i].dot(s.H0m.col(j))});  // i above k, k on the path to j
      for (int j : t.above[k])  // k below both; the joints above k are ordered by index
        if (i <= j) entries.push_back({i, j, SxSk[i].dot(IcS[j]) + SxSk[j].dot(IcS[i])});
    }
  }
  Mat6 Omega = Mat6::Zero();
  Omega.topLeftCorner<3, 3>() = Omega.bottomRightCorner<3, 3>() = skew(s.x0dot.tail<3>());
  d.H0dot = Omega * s.H0 - s.H0 * Omega;
  d.H0mdot = Omega * s.H0m;
  for (int k = 0; k < n; ++k) {
    const double qk = s.qdot[k];
    d.H0dot += qk * Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(d.dH0.data() + 36 * k);
    d.add_dH0m(k, qk, d.H0mdot);
  }
}

bool admissible(const Tree& t, const double* q, int nq, const double* v, int nv, double tolerance, double largest) {
  for (int i = 0; i < nq; ++i)
    if (!(std::abs(q[i]) <= largest)) return false;  // NaN fails too
  for (int i = 0; i < nv; ++i)
    if (!(std::abs(v[i]) <= largest)) return false;
  const auto unit = [&](int i, int size) {
    double norm = 0.0;
    for (int j = i; j < i + size; ++j) norm += q[j] * q[j];
    return std::abs(std::sqrt(norm) - 1.0) < tolerance;
  };
  if (!(t.free_base ? unit(3, 4) : unit(2, 2))) return false;
  for (int j = 0; j < t.n; ++j)
    if (t.circle[j] && !unit(t.q_index[j], 2)) return false;
  return true;
}

}  // namespace freefloat
