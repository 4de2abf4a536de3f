// Solves with the GJM mass matrix of a tree, H = [[H0, H0m], [H0m^T, Hm]] over z = [x0dot; qdot]
// (6 + n coordinates; base twist [v0; w0] of the base CoM, inertial frame), in O(n d^2) to factor
// and O(n d) per right-hand side for a tree of depth d, where the dense H* = Hm - H0m^T H0^-1 H0m
// costs O(n^3). Branch-induced sparsity (Featherstone, RBDA sec 6.5): H(i, j) is zero unless one of
// coordinates i, j is an ancestor of the other, with the six base coordinates an ancestor chain of
// every joint. H = L^T D L with L unit lower triangular of the same pattern, eliminated from the
// leaves to the base (LTDL): no fill-in. Solving H [xddot0; qddot] = [0; r] gives the qddot of
// H* qddot = r, since the base row eliminates to exactly H*. Defined in models.cpp.
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
  explicit TreeSolver(const Tree& t);

  // H at the state of compute_inertia: H0, H0m[:, j] = Ic_{j+1} S_j, Hm[i, j] = S_i . H0m[:, j]
  // for joint i above joint j. Then factored.
  void factor(const State& s);

  // LTDL in place: coordinate k (leaves first) is eliminated into its ancestors, whose own
  // ancestor lists are the tails of k's.
  void factor();

  // x <- H^-1 x (N,): L^-T, D^-1, L^-1.
  void solve(double* x) const;
};

}  // namespace freefloat
