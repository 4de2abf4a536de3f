// The GJM quantities (dissertation secs 3.1-3.4) and their joint and time derivatives (sec 3.2.1),
// compiled. The numpy modules freefloat/dynamics/gjm/{kinematics,matrices,model,derivatives}.py are
// the equation-by-equation reference; tests/test_gjm_compiled.py pins the two equal.
//
// Every vector is in the inertial frame. Spatial quantities are taken about the base CoM r0 (which
// no joint moves) in [linear; angular] order:
//   joint j's motion  S_j = [k_j x (r0 - p_j); k_j] (revolute), [k_j; 0] (prismatic),
//   body b's inertia  I_b = [[m I, -m c^x], [m c^x, I_c - m c^x c^x]],  c = r_b - r0,
//   so that h = I_b [v0; w0] = [P; L about r0]. Composite inertias Ic_b sum the subtree of body b.
// Then H0 = Ic_0 (eq 23), H0m[:, j] = Ic_{j+1} S_j (eq 22), Hm[i, j] = S_i . H0m[:, j] for joint i
// on the path to joint j (eq 19; zero between branches). Joint k moves everything it carries
// rigidly with the motion S_k: a motion vector X by S_k x X, a momentum F by S_k x* F, an inertia
// by S_k x* I - I S_k x.
//
// Cost: everything a dynamics model needs (compute_inertia, derivatives) is O(n d^2) for a tree of
// depth d, the joint derivatives kept as their nonzero entries and columns; only the dense outputs
// of compute_generalized_inertia (Hm, H*) and compute_jacobians (Jm, J*) and the dense derivative
// arrays handed to numpy grow as n^2
// (n^3 for dHm/dq).
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <vector>

namespace freefloat {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using MatX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Mat6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;  // (6, n), one contiguous column per joint
using VecX = Eigen::VectorXd;

inline Mat3 skew(const Vec3& x) {
  Mat3 out;
  out << 0.0, -x.z(), x.y(), x.z(), 0.0, -x.x(), -x.y(), x.x(), 0.0;
  return out;
}

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

// Static description of the tree (what TreeStructure holds in numpy), read once per robot.
struct Tree {
  int n = 0;                       // actuated joints; body b >= 1 is moved by joint b - 1
  std::vector<int> parent;         // (n) parent body of body j + 1, 0 = base; parent < child
  std::vector<Mat3> place_R;       // (n) joint placement in the parent body frame
  std::vector<Vec3> place_t;
  std::vector<Vec3> axis;          // (n) unit axis in the joint frame
  std::vector<char> revolute;      // (n) revolute, else prismatic
  std::vector<double> mass;        // (n + 1) base first
  std::vector<Vec3> com;           // (n + 1) CoM in the body frame (base: base-link frame)
  std::vector<Mat3> inertia;       // (n + 1) rotational inertia about the CoM, body frame
  std::vector<char> moves;         // (n + 1) x n: moves[b * n + j], joint j moves body b
  std::vector<int> q_index;        // (n) index of joint j in q
  std::vector<char> circle;        // (n) stored as [cos, sin] in q
  bool free_base = true;           // free-flyer [p; quat xyzw], else planar [x, y, cos, sin]
  Vec3 base_com = Vec3::Zero();    // base CoM in the base-link frame
  Mat3 base_com_rotation = Mat3::Identity();
  std::vector<int> ee_body;        // (k) body of each end-effector, 0 = base
  std::vector<Vec3> ee_offset;     // (k) end-effector origin in that body frame

  std::vector<std::vector<int>> above;   // (n) the joints strictly on the path to joint k
  std::vector<std::vector<int>> carried;  // (n) the joints joint k carries, itself included

  int bodies() const { return n + 1; }
  // joint k carries joint j's frame (k == j included): k is on the path to j.
  bool carries(int k, int j) const { return moves[(j + 1) * n + k] != 0; }

  // Fill `above` and `carried` from `moves`.
  void index_paths() {
    above.assign(n, {});
    carried.assign(n, {});
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j) {
        if (carries(k, j)) carried[k].push_back(j);
        if (j != k && carries(j, k)) above[k].push_back(j);
      }
  }
};

// Body kinematics at one configuration (numpy: BodyKinematics), inertial frame.
struct Kinematics {
  Vec3 r0;
  Mat3 R0;
  std::vector<Mat3> rotation;   // (n + 1)
  std::vector<Vec3> origin;     // (n + 1), the base's is the base-link origin
  std::vector<Vec3> joint_axis; // (n)
  std::vector<Vec3> com;        // (n + 1)
  std::vector<Mat3> inertia;    // (n + 1) about the CoM, inertial axes
};

struct State {
  Kinematics kin;
  Mat6 H0;
  Mat6X H0m;
  MatX Hm, Hstar, J0;                    // compute_generalized_inertia only
  MatX Jm, J0E, Jstar, ee_position;      // compute_jacobians only
  Vec6 momentum_base, momentum_origin, x0dot;
  VecX qdot;
  std::vector<Vec6> S;          // (n) joint motions about r0
  std::vector<Mat6> Ic;         // (n + 1) composite inertias about r0
  Eigen::LDLT<Mat6> H0_ldlt;
  Mat6 H0_inv;                  // H0^-1, for solve0
};

struct Derivatives {
  std::vector<double> dH0;      // (n, 6, 6) C order
  struct Column {
    int j;
    Vec6 value;
  };
  // (n) dH0m/dq_k (6, n): its nonzero columns, those of the joints k carries or that are above k.
  std::vector<std::vector<Column>> dH0m_columns;
  struct Entry {
    int i, j;
    double value;
  };
  std::vector<std::vector<Entry>> dHm_entries;  // (n) dHm/dq_k (n, n): its nonzero entries, i <= j
  Mat6 H0dot;
  Mat6X H0mdot;

  // x^T dHm/dq_k x from the nonzero entries.
  double dHm_form(int k, const VecX& x) const {
    double out = 0.0;
    for (const Entry& e : dHm_entries[k]) out += (e.i == e.j ? 1.0 : 2.0) * e.value * x[e.i] * x[e.j];
    return out;
  }
  // dH0m/dq_k x (6,).
  Vec6 dH0m_times(int k, const VecX& x) const {
    Vec6 out = Vec6::Zero();
    for (const Column& c : dH0m_columns[k]) out += x[c.j] * c.value;
    return out;
  }
  // out += w dH0m/dq_k.
  void add_dH0m(int k, double w, Mat6X& out) const {
    for (const Column& c : dH0m_columns[k]) out.col(c.j) += w * c.value;
  }
  // Hmdot x = sum_k qdot_k dHm/dq_k x (n,).
  VecX Hmdot_times(const VecX& qdot, const VecX& x) const {
    VecX out = VecX::Zero(x.size());
    for (size_t k = 0; k < dHm_entries.size(); ++k)
      for (const Entry& e : dHm_entries[k]) {
        out[e.i] += qdot[k] * e.value * x[e.j];
        if (e.i != e.j) out[e.j] += qdot[k] * e.value * x[e.i];
      }
    return out;
  }
};

// Base-link pose and the base twist x0dot = [v0; w0] (base CoM, inertial) from Pinocchio's q, v.
inline void base_state(const Tree& t, const double* q, const double* v, Mat3& R, Vec3& p, Vec6& x0dot) {
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

// What every dynamics model needs at (q, v), in O(n): body kinematics, joint motions S, composite
// inertias Ic, H0 (and its factorisation), H0m, the base twist, joint rates and momenta.
inline void compute_inertia(const Tree& t, const double* q, const double* v, State& s) {
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

// H0^-1 X for X (6, n), column by column through H0^-1 (Eigen's dynamic-size solve packs and
// blocks, which costs more than the products on these sizes).
inline Mat6X solve0(const State& s, const Mat6X& X) {
  Mat6X out(6, X.cols());
  for (Eigen::Index j = 0; j < X.cols(); ++j) out.col(j).noalias() = s.H0_inv * X.col(j);
  return out;
}

// Hm, J0 and H* after compute_inertia: Hm filled along the paths only, H* = Hm + H0m^T J0 row by
// row on and above the diagonal, mirrored.
inline void compute_generalized_inertia(const Tree& t, State& s) {
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

// The end-effector points, Jm, J0E and J* = Jm + J0E J0 with J0E's blocks [[I, -(r_E - r0)x],
// [0, I]] written out, after compute_generalized_inertia (J0).
inline void compute_jacobians(const Tree& t, State& s) {
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

// All GJM quantities at (q, v) (numpy: GJM.compute).
inline void compute(const Tree& t, const double* q, const double* v, State& s) {
  compute_inertia(t, q, v, s);
  compute_generalized_inertia(t, s);
  compute_jacobians(t, s);
}

// Joint derivatives at fixed base pose and twist, and time derivatives along the motion
// (numpy: derivatives.time_derivatives), from a state computed by compute_inertia(). dH0m/dq_k is
// kept as its nonzero columns and dHm/dq_k as its nonzero entries.
inline void derivatives(const Tree& t, const State& s, Derivatives& d) {
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

}  // namespace freefloat
