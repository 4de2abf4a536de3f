// The inverse side of mechanism.hpp's closed chains: inverse dynamics (eqs 130-140), Newton
// assembly (a least-squares step at a singular A°) and the inverse dynamics along a path by
// continuation (MechanismCore's inverse, assemble and trajectory). A translation unit without
// pybind11, at -O3; the point evaluations it calls are in mechanism.cpp.
#include <Eigen/LU>
#include <Eigen/QR>

#include "mechanism.hpp"

namespace freefloat {

void Mechanism::inverse(const double* q, const double* qd_sharp, const double* qdd_sharp, DVec& tau, DVec& qd,
                        DVec& qdd, DMat& C) {
  DVec residual;
  DMat A;
  closure(q, residual, A);
  inverse_at(A, qd_sharp, qdd_sharp, tau, qd, qdd, C);
}

void Mechanism::inverse_at(const DMat& A, const double* qd_sharp, const double* qdd_sharp, DVec& tau, DVec& qd,
                           DVec& qdd, DMat& C) {
  DVec b, v, g;
  DMat M;
  const Eigen::PartialPivLU<DMat> lu = passive_lu(A);
  C = velocity_map(A, lu);
  qd = C * Eigen::Map<const DVec>(qd_sharp, p);
  dynamics(qd.data(), b, M, v, g);
  const DVec vg = v + g;
  qdd = C * Eigen::Map<const DVec>(qdd_sharp, p);
  qdd.tail(n_q - p) += lu.solve(b);
  const DMat CT = C.transpose();
  tau = (CT * U).partialPivLu().solve(CT * (M * qdd + vg));
}

bool Mechanism::assemble(DVec& q, double tol, int iterations, DMat& A) {
  DVec residual;
  for (int it = 0; it < iterations; ++it) {
    closure(q.data(), residual, A);
    if (residual.cwiseAbs().maxCoeff() < tol) return true;
    const DMat Ao = A.rightCols(n_q - p);
    Eigen::PartialPivLU<DMat> lu(Ao);
    const auto diag = lu.matrixLU().diagonal();
    bool singular = false;
    for (int i = 0; i < diag.size(); ++i) singular = singular || diag[i] == 0.0;
    q.tail(n_q - p) -= singular ? DVec(Ao.completeOrthogonalDecomposition().solve(residual)) : DVec(lu.solve(residual));
  }
  return false;
}

std::pair<int, Eigen::Index> Mechanism::trajectory(Eigen::Index N, const double* x, const double* xd,
                                                   const double* xdd, const double* guess, double jump, double tol,
                                                   int iterations, double* q_rows, double* tau_rows) {
  using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Index nq = n_q;
  Eigen::Map<RowMat> Q(q_rows, N, nq), T(tau_rows, N, U.cols());
  DVec anchor(nq), q(nq), tau, qd, qdd;
  DMat C, A;
  anchor << Eigen::Map<const DVec>(x, p), Eigen::Map<const DVec>(guess, nq - p);
  if (!assemble(anchor, tol, iterations, A)) {
    Q.row(0) = anchor.transpose();
    return {1, 0};
  }
  C = velocity_map(A);
  int status = 0;
  Eigen::Index i = 0;
  for (; i < N; ++i) {
    const Eigen::Map<const DVec> xi(x + i * p, p);
    q << xi, anchor.tail(nq - p) + C.bottomRows(nq - p) * (xi - anchor.head(p));
    const DVec predicted = q.tail(nq - p);
    if (!assemble(q, tol, iterations, A)) {
      q.tail(nq - p) = predicted;
      status = 1;
    } else if ((q.tail(nq - p) - predicted).cwiseAbs().maxCoeff() > jump) {
      status = 2;
    }
    Q.row(i) = q.transpose();
    if (status) break;
    inverse_at(A, xd + i * p, xdd + i * p, tau, qd, qdd, C);
    T.row(i) = tau.transpose();
    anchor = q;
  }
  return {status, i};
}

}  // namespace freefloat
