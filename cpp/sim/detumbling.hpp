// The post-capture detumbling solver of freefloat.space.detumbling.solve (dissertation sec 3.8.1,
// eqs 115-120 and 134) on the quantities of generalized_jacobian.hpp:
//   J*{k,S} qdot_S = -J0E{k} H0^-1 M,  qdot outside S = 0,
// methods single (eq 120), min_norm and least_squares (pseudo-inverse), null_space (min-norm plus
// the null-space motion minimising the base angular velocity or the whole base twist).
#pragma once

#include <Eigen/QR>
#include <Eigen/SVD>

#include <cstdio>
#include <string>
#include <vector>

#include "generalized_jacobian.hpp"

namespace freefloat::sim {

// The Moore-Penrose pseudo-inverse with numpy.linalg.pinv's cut: singular values not above
// rcond times the largest are dropped (their count left in `rank` if given).
inline Eigen::MatrixXd pinv(const Eigen::MatrixXd& A, double rcond, int* rank = nullptr) {
  if (rank != nullptr) *rank = 0;
  if (A.size() == 0) return Eigen::MatrixXd::Zero(A.cols(), A.rows());
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Vec& s = svd.singularValues();
  const double cutoff = rcond * s.maxCoeff();
  if (rank != nullptr) *rank = static_cast<int>((s.array() > cutoff).count());
  const Vec inverse = (s.array() > cutoff).select(s.cwiseInverse(), 0.0);
  return svd.matrixV() * inverse.asDiagonal() * svd.matrixU().transpose();
}

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

  void compute(const Eigen::MatrixXd& A, double rcond) {
    rows = static_cast<int>(A.rows());
    full = rows > 0 && rows <= 12 && rows <= A.cols() && rcond <= 1e-10;
    if (full) {
      qr.compute(A.transpose());
      const auto R = qr.matrixR().diagonal().head(rows).cwiseAbs();
      full = R.minCoeff() > kFullRank * R[0];
    }
    if (!full) P = pinv(A, rcond);
  }

  Vec solve(const Vec& b) const {
    if (!full) return P * b;
    Vec z = Vec::Zero(qr.rows());
    z.head(rows) = qr.matrixR().topLeftCorner(rows, rows).triangularView<Eigen::Upper>().transpose().solve(
        Vec(qr.colsPermutation().transpose() * b));
    return qr.householderQ() * z;
  }
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
inline std::string solve(const GeneralizedJacobian& g, const DetumblingTask& task, Vec& qdot, Vec& residual) {
  const int r = static_cast<int>(task.rows.size()), s = static_cast<int>(task.joints.size());
  Eigen::MatrixXd A(r, s);
  Vec drift(r);
  for (int i = 0; i < r; ++i) {
    drift[i] = g.drift[task.rows[i]];
    for (int j = 0; j < s; ++j) A(i, j) = g.Jstar(task.rows[i], task.joints[j]);
  }
  Vec qS;
  if (task.method == DetumblingTask::Method::single) {
    if (std::abs(A(0, 0)) < task.rcond * std::max(1.0, g.Jstar.cwiseAbs().maxCoeff())) {
      char text[160];
      std::snprintf(text, sizeof text, "mission joint %d does not move row %d (coefficient %.2e): choose another",
                    task.joints[0], task.rows[0], A(0, 0));
      return text;
    }
    qS = -drift / A(0, 0);
  } else {
    const Eigen::MatrixXd P = pinv(A, task.rcond);
    qS = -P * drift;
    if (task.method == DetumblingTask::Method::null_space) {
      const Eigen::MatrixXd N = Eigen::MatrixXd::Identity(s, s) - P * A;
      const int first = task.whole_twist ? 0 : 3, count = 6 - first;
      Eigen::MatrixXd C(count, s);
      for (int j = 0; j < s; ++j) C.col(j) = g.J0.col(task.joints[j]).segment(first, count);
      const Vec d = C * qS + g.base_twist.segment(first, count);
      qS += N * (-pinv(C * N, task.rcond) * d);
    }
  }
  qdot.setZero(g.Jstar.cols());
  for (int j = 0; j < s; ++j) qdot[task.joints[j]] = qS[j];
  residual.resize(r);
  for (int i = 0; i < r; ++i) residual[i] = g.Jstar.row(task.rows[i]).dot(qdot) + drift[i];
  return {};
}

}  // namespace freefloat::sim
