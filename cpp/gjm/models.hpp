// The GJM dynamics models of freefloat.models (docs/models.md), compiled. The numpy classes in
// freefloat/dynamics/models/{gjm_base,underactuated,generalized}.py are the reference, with the
// equations; each function of models.cpp names the method it mirrors. tests/test_models.py pins
// the two.
//
// Every model writes the joints as tau + Q_q = H qddot + c and the base row as xddot0 = f(qddot),
// xddot0 the acceleration of the base CoM twist [v0; w0] (inertial frame). Every term here is
// O(n d^2) for a tree of depth d: the joint partials are contracted through their nonzero columns
// and entries, NIDC's augmentation is applied to vectors, and forward dynamics solves H = H* through
// the tree-sparse factorisation of the whole mass matrix (tree_solve.hpp) where the numpy reference
// forms and solves the dense H*.
//
// This header declares what the bindings (bindings/core.cpp) call; models.cpp defines it.
#pragma once

#include <string>
#include <vector>

#include "gjm.hpp"
#include "tree_solve.hpp"

namespace freefloat {

enum class Variant {
  standard, standard_full_hdot, standard_corrected, nidc, nidc_translation,
  reduced, momentum_mono, momentum_multi, momentum_routh
};

// The names of Variant, in its order (exported as _core.MODELS; tests/test_models.py checks them
// against freefloat.dynamics.models.MODELS).
const std::vector<std::string>& variant_names();

// The Variant of a name of variant_names(); std::invalid_argument for another name.
Variant variant_of(const std::string& name);

// One model's joint-space form and base row at the state of (s, d).
struct ModelResult {
  VecX c;            // tau + Q_q = H* qddot + c (all variants use H = H*)
  Vec6 base_bias;    // xddot0 = -H0^-1 (H0m qddot + base_bias)
};

// The named model's joint-space form and base row at the state of (s, d): F (6,) the base rows'
// generalized force, D NIDC's (n, 6) sensitivity rows (nidc variants only).
ModelResult model_terms(const Tree& t, const State& s, const Derivatives& d, Variant variant, const Vec6& F,
                        const MatX& D);

// NIDCModel.xdot0_sensitivity (n, 6) at the state of (s, d), with the partials augmented by D (n, 6).
MatX nidc_sensitivity(const Tree& t, const State& s, const Derivatives& d, const MatX& D, bool translation);

// conventions.local_base_acceleration: Pinocchio's base acceleration (6, free; first 3 rows of
// the embedding [0, 1, 5] for planar) from xddot0.
void local_base_acceleration(const Tree& t, const double* q, const double* v, const Vec6& xddot0, double* out);

// GJMModel.acceleration, the named model's forward dynamics at the state of (s, d) (compute_inertia
// and derivatives at q, v): Pinocchio's acceleration a (nv,) under the joints' efforts tau (n,) and
// generalized forces Q_q (n,), F and D as in model_terms. H* qddot = tau + Q_q - c is solved
// through the tree-sparse factorisation of the whole GJM mass matrix (`solver`, factored here at
// s), never forming H*; then xddot0 and the base rows of a.
void forward_dynamics(const Tree& t, const State& s, const Derivatives& d, TreeSolver& solver, Variant variant,
                      const Vec6& F, const MatX& D, const double* tau, const double* Q_q, const double* q,
                      const double* v, int nv, double* a);

}  // namespace freefloat
