// The definitions of sim/detumbling.hpp: the pseudo-inverse, the least-norm solver and the
// detumbling solve, on Eigen's SVD and column-pivoted QR (no Pinocchio, no pybind11).
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "detumbling.hpp"

namespace freefloat::sim {

Eigen::MatrixXd pinv(const Eigen::MatrixXd& A, double rcond, int* rank) {
  if (rank != nullptr) *rank = 0;
  if (A.size() == 0) return Eigen::MatrixXd::Zero(A.cols(), A.rows());
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Vec& s = svd.singularValues();
  const double cutoff = rcond * s.maxCoeff();
  if (rank != nullptr) *rank = static_cast<int>((s.array() > cutoff).count());
  const Vec inverse = (s.array() > cutoff).select(s.cwiseInverse(), 0.0);
  return svd.matrixV() * inverse.asDiagonal() * svd.matrixU().transpose();
}

void LeastNorm::compute(const Eigen::MatrixXd& A, double rcond) {
  rows = static_cast<int>(A.rows());
  full = rows > 0 && rows <= 12 && rows <= A.cols() && rcond <= 1e-10;
  if (full) {
    qr.compute(A.transpose());
    const auto R = qr.matrixR().diagonal().head(rows).cwiseAbs();
    full = R.minCoeff() > kFullRank * R[0];
  }
  if (!full) P = pinv(A, rcond);
}

Vec LeastNorm::solve(const Vec& b) const {
  if (!full) return P * b;
  Vec z = Vec::Zero(qr.rows());
  z.head(rows) = qr.matrixR().topLeftCorner(rows, rows).triangularView<Eigen::Upper>().transpose().solve(
      Vec(qr.colsPermutation().transpose() * b));
  return qr.householderQ() * z;
}

std::string solve(const GeneralizedJacobian& g, const DetumblingTask& task, Vec& qdot, Vec& residual) {
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
