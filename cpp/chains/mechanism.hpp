// Orsino's closed chains (freefloat.parallel), compiled for one point at a time: the serial chains'
// kinematics and dynamics (serial.py, eqs 22-64), the coupling's closure, forward dynamics
// (eq 129), inverse dynamics (eqs 130-140), Newton assembly and the inverse dynamics along a path
// by continuation. The numpy code in serial.py and mechanism.py is the reference (with the
// equations); tests/test_mechanism.py pins the two. Every vector is in the inertial frame N.
// Declarations on Eigen/Core only: the numerics are in mechanism.cpp and inverse.cpp, so that the
// bindings (bindings/chains.cpp) compile without Eigen's dense solvers.
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <utility>
#include <vector>

namespace freefloat {

using Mat4 = Eigen::Matrix4d;
using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;
using DMat = Eigen::MatrixXd;
using DVec = Eigen::VectorXd;

// A point the mechanism cannot handle (singular pose): becomes a FreefloatError in Python.
struct MechanismError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// SerialChain: joint frames J_i = B_{i-1} P_i, link frames B_i = J_i Rz(q_i) L_i (or Tz).
struct Chain {
  int nu = 0;
  std::vector<Mat4> placement, link, link_next;  // link_next[i] = L_i P_{i+1}
  std::vector<char> prismatic;
  std::vector<double> mass;
  std::vector<V3> com;
  std::vector<M3> inertia;
  Mat4 base = Mat4::Identity();
  V3 tip_point = V3::Zero(), gravity = V3::Zero();
};

// One chain at (q, qd): what the coupling needs.
struct ChainState {
  V3 x;                       // tip point
  M3 R_tip;                   // last link's rotation
  DMat tip_Jv, tip_Jw;        // (3, nu)
  V3 tip_c, tip_dw;           // acceleration biases of the tip point and the last link's rotation
  DMat M;                     // (nu, nu)
  DVec v, g;                  // (nu)
  std::vector<V3> k, o;       // joint axes and points (nu)
  std::vector<Mat4> H;        // link frames (nu + 1)
};

// ParallelMechanism with a square passive Jacobian A° (the compiled path).
struct Mechanism {
  std::vector<Chain> chains;
  int p = 0, n_q = 0, m_lin = 0, m_ang = 0;
  DMat D, E, F, platform_mass, U;
  DVec d, platform_gravity;
  bool angular = false;
  DMat P, Q, R;
  std::vector<M3> reference;
  DVec offset;
  std::vector<ChainState> states;
  DVec x_buf, phi_buf, tip_c_buf, tip_dw_buf;  // reused between calls
  DMat Jv_buf, Jw_buf;
  // The last closure evaluated: its q, residual and A (the chains' frames in `states` are its
  // too). A step's drift check and the next step's first stage (and a law on the same model)
  // ask for the same q; they take it from here.
  DVec closure_q, closure_residual;
  DMat closure_A;

  int m() const { return m_lin + m_ang; }

  // mechanism._closure: [qbar; orientation residual] (m) and A (m, n_q) at q, chain frames left in states.
  void closure(const double* q, DVec& residual, DMat& A);
  void evaluate_closure(const double* q, DVec& residual, DMat& A);

  // _dynamics_terms at qd after closure(q): b (m), M' (n_q, n_q), v' (n_q), g' (n_q).
  void dynamics(const double* qd, DVec& b, DMat& M, DVec& v, DVec& g);

  // passive_solve with an LU of the square A°; a zero pivot is a singular pose.
  Eigen::PartialPivLU<DMat> passive_lu(const DMat& A) const;

  // _velocity_map: C = [I; -A°^-1 A#] (n_q, p), from A's LU (passive_lu) or from A alone.
  DMat velocity_map(const DMat& A, const Eigen::PartialPivLU<DMat>& lu) const;
  DMat velocity_map(const DMat& A) const;

  // forward: qddot (n_q) under efforts tau (k), eq 129 with lambda = baumgarte.
  DVec forward(const double* q, const double* qd, const double* tau, double baumgarte);

  // inverse at an assembled q: efforts tau (k), qd, qdd (n_q) and C (n_q, p) at q (eqs 130-140).
  void inverse(const double* q, const double* qd_sharp, const double* qdd_sharp, DVec& tau, DVec& qd, DVec& qdd,
               DMat& C);

  // inverse with the closure (A and the chains' frames) already evaluated at q.
  void inverse_at(const DMat& A, const double* qd_sharp, const double* qdd_sharp, DVec& tau, DVec& qd, DVec& qdd,
                  DMat& C);

  // assemble: Newton on qbar = 0 for the chains' joints from q's passive part; false when it
  // does not converge in `iterations` steps. A singular A° takes the least-squares step.
  // On success A (and the chains' frames) are those at the returned q.
  bool assemble(DVec& q, double tol, int iterations, DMat& A);

  // The inverse dynamics along a path of N platform points x (N, p), with rates xd and
  // accelerations xdd (N, p), by continuation from [x_0; guess] (guess (n_q - p)): fills the rows
  // of q_rows (N, n_q) and tau_rows (N, k), row-major. Returns (status, index): 0 when every
  // point was solved (index N); 1 when no assembly at index (its q row holds the prediction, at
  // index 0 the start [x_0; guess]); 2 at a jump of the passive joints larger than `jump` at index.
  std::pair<int, Eigen::Index> trajectory(Eigen::Index N, const double* x, const double* xd, const double* xdd,
                                          const double* guess, double jump, double tol, int iterations,
                                          double* q_rows, double* tau_rows);
};

}  // namespace freefloat
