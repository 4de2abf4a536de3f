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
//
// This header holds the types and the small helpers the models' loops call (skew, Derivatives'
// contractions); the functions are defined in gjm.cpp.
#pragma once

#include <Eigen/Dense>
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
void base_state(const Tree& t, const double* q, const double* v, Mat3& R, Vec3& p, Vec6& x0dot);

// What every dynamics model needs at (q, v), in O(n): body kinematics, joint motions S, composite
// inertias Ic, H0 (and its factorisation), H0m, the base twist, joint rates and momenta.
void compute_inertia(const Tree& t, const double* q, const double* v, State& s);

// H0^-1 X for X (6, n), column by column through H0^-1 (Eigen's dynamic-size solve packs and
// blocks, which costs more than the products on these sizes).
Mat6X solve0(const State& s, const Mat6X& X);

// Hm, J0 and H* after compute_inertia: Hm filled along the paths only, H* = Hm + H0m^T J0 row by
// row on and above the diagonal, mirrored.
void compute_generalized_inertia(const Tree& t, State& s);

// The end-effector points, Jm, J0E and J* = Jm + J0E J0 with J0E's blocks [[I, -(r_E - r0)x],
// [0, I]] written out, after compute_generalized_inertia (J0).
void compute_jacobians(const Tree& t, State& s);

// All GJM quantities at (q, v) (numpy: GJM.compute).
void compute(const Tree& t, const double* q, const double* v, State& s);

// Joint derivatives at fixed base pose and twist, and time derivatives along the motion
// (numpy: derivatives.time_derivatives), from a state computed by compute_inertia(). dH0m/dq_k is
// kept as its nonzero columns and dHm/dq_k as its nonzero entries.
void derivatives(const Tree& t, const State& s, Derivatives& d);

// Whether (q, v) passes freefloat.robot.state.check_state: every number finite and at most
// `largest` in size, every unit-norm block of q (base quaternion, planar base's and continuous
// joints' (cos, sin)) within `tolerance` of norm 1 (as pin.isNormalized). Sizes are not checked.
bool admissible(const Tree& t, const double* q, int nq, const double* v, int nv, double tolerance, double largest);

}  // namespace freefloat
