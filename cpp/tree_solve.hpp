// Solves with the GJM mass matrix of a tree, H = [[H0, H0m], [H0m^T, Hm]] over z = [x0dot; qdot]
// (6 + n coordinates; base twist [v0; w0] of the base CoM, inertial frame), in O(n d^2) to factor
// and O(n d) per right-hand side for a tree of depth d, where the dense H* = Hm - H0m^T H0^-1 H0m
// costs O(n^3). Branch-induced sparsity (Featherstone, RBDA sec 6.5): H(i, j) is zero unless one of
// coordinates i, j is an ancestor of the other, with the six base coordinates an ancestor chain of
// every joint. H = L^T D L with L unit lower triangular of the same pattern, eliminated from the
// leaves to the base (LTDL): no fill-in. Solving H [xddot0; qddot] = [0; r] gives the qddot of
// H* qddot = r, since the base row eliminates to exactly H*.
#pragma once

#include <vector>

#include "gjm.hpp"

namespace freefloat {

struct TreeSolver {
  int N = 0;                  // 6 + n
  std::vector<int> start;     // (N + 1): coordinate i's ancestors are ancestor[start[i]:start[i + 1]], nearest first
  std::vector<int> ancestor;
  std::vector<double> value;  // H(i, ancestor) on filling; L(i, ancestor) after factor()
  VecX D;                     // (N) H(i, i); then D

  // The pattern of a tree: base coordinate b has the base coordinates below it; joint j (coordinate
  // 6 + j) the joints above it, nearest first, then the base coordinates 5, ..., 0.
  explicit TreeSolver(const Tree& t) : N(6 + t.n), start(N + 1, 0), D(N) {
    for (int i = 0; i < N; ++i) {
      if (i >= 6)
        for (auto a = t.above[i - 6].rbegin(); a != t.above[i - 6].rend(); ++a) ancestor.push_back(6 + *a);
      for (int b = (i < 6 ? i : 6) - 1; b >= 0; --b) ancestor.push_back(b);
      start[i + 1] = static_cast<int>(ancestor.size());
    }
    value.resize(ancestor.size());
  }

  // H at the state of compute_inertia: H0, H0m[:, j] = Ic_{j+1} S_j, Hm[i, j] = S_i . H0m[:, j]
  // for joint i above joint j. Then factored.
  void factor(const State& s) {
    for (int i = 0; i < N; ++i) {
      const int j = i - 6;
      D[i] = j < 0 ? s.H0(i, i) : s.S[j].dot(s.H0m.col(j));
      for (int m = start[i]; m < start[i + 1]; ++m) {
        const int a = ancestor[m];
        value[m] = j < 0 ? s.H0(i, a) : a < 6 ? s.H0m(a, j) : s.S[a - 6].dot(s.H0m.col(j));
      }
    }
    factor();
  }

  // LTDL in place: coordinate k (leaves first) is eliminated into its ancestors, whose own
  // ancestor lists are the tails of k's.
  void factor() {
    for (int k = N - 1; k >= 0; --k) {
      const int first = start[k], last = start[k + 1];
      for (int m = first; m < last; ++m) {
        const int i = ancestor[m];
        const double a = value[m] / D[k];
        D[i] -= a * value[m];
        double* row = value.data() + start[i] - (m + 1);  // row[m2] is H(i, ancestor[m2]) for m2 > m
        for (int m2 = m + 1; m2 < last; ++m2) row[m2] -= a * value[m2];
        value[m] = a;
      }
    }
  }

  // x <- H^-1 x (N,): L^-T, D^-1, L^-1.
  void solve(double* x) const {
    for (int k = N - 1; k >= 0; --k)
      for (int m = start[k]; m < start[k + 1]; ++m) x[ancestor[m]] -= value[m] * x[k];
    for (int k = 0; k < N; ++k) x[k] /= D[k];
    for (int k = 0; k < N; ++k)
      for (int m = start[k]; m < start[k + 1]; ++m) x[k] -= value[m] * x[ancestor[m]];
  }
};

}  // namespace freefloat
