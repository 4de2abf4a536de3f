// The post-capture detumbling solver of freefloat.space.detumbling.solve (dissertation sec 3.8.1,
// eqs 115-120 and 134) on the quantities of generalized_jacobian.hpp:
//   J*{k,S} qdot_S = -J0E{k} H0^-1 M,  qdot outside S = 0,
// methods single (eq 120), min_norm and least_squares (pseudo-inverse), null_space (min-norm plus
// the null-space motion minimising the base angular velocity or the whole base twist).
// Declarations: the definitions are in detumbling.cpp, a translation unit of its own (Eigen
// only), so that the SVD and QR are compiled once, apart from Pinocchio and pybind11.
#pragma once

#include <Eigen/QR>

#include <stdexcept>
#include <string>
#include <vector>

#include "generalized_jacobian.hpp"

namespace freefloat::sim {

// The Moore-Penrose pseudo-inverse with numpy.linalg.pinv's cut: singular values not above
// rcond times the largest are dropped (their count left in `rank` if given).
Eigen::MatrixXd pinv(const Eigen::MatrixXd& A, double rcond, int* rank = nullptr);

// x = pinv(A, rcond) b for many b, as pinv() gives it, faster: when a column-pivoted QR of A^T
// shows A (m <= 12 rows) of full row rank by a wide margin (every |R_kk| above kFullRank |R_00|:
// then sigma_max <= sqrt(m) |R_00| and sigma_min >= |R_kk| 3 / sqrt(4^m + 6m - 1), so every
// singular value is above 2e-10 times the largest and pinv(A, rcond <= 1e-10) keeps them all), x is
// the unique least-norm solution Q R^-T P^T b; otherwise pinv() itself (the SVD, numpy's cut).
// The two agree to round-off where both apply.
struct LeastNorm {
  static constexpr double kFullRank = 1e-6;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr;
  Eigen::MatrixXd P;  // pinv(A) when A is not clearly of full row rank
  bool full = false;
  int rows = 0;

  void compute(const Eigen::MatrixXd& A, double rcond);
  Vec solve(const Vec& b) const;
};

struct DetumblingTask {
  enum class Method { single, min_norm, null_space, least_squares };
  std::vector<int> rows;    // stacked rows k into the 6k rows [v_E; w_E] per end-effector
  std::vector<int> joints;  // mission joints S into the actuated joints
  Method method = Method::min_norm;
  bool whole_twist = false;  // null_space: minimise the base twist, not only its angular velocity
  double rcond = 1e-10;

  static Method method_named(const std::string& name) {
    if (name == "single") return Method::single;
    if (name == "min_norm") return Method::min_norm;
    if (name == "null_space") return Method::null_space;
    if (name == "least_squares") return Method::least_squares;
    throw std::invalid_argument("unknown detumbling method '" + name + "'");
  }
};

// Joint rates qdot (n,) and residual J*{k} qdot + J0E{k} H0^-1 M (len(k),). Returns an empty
// string, or detumbling.solve's message when `single`'s mission joint cannot move its row.
// (The shape rules of detumbling.solve are checked in Python before a task gets here.)
std::string solve(const GeneralizedJacobian& g, const DetumblingTask& task, Vec& qdot, Vec& residual);

}  // namespace freefloat::sim
