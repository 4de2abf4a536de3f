// The generalized Jacobian quantities of one state (dissertation eqs 69-89, the same numbers as
// freefloat.dynamics.gjm.GJMState), as the compiled loop's laws and its Python interface take them;
// pin_generalized_jacobian.hpp computes them on a Pinocchio model.
#pragma once

#include "eigen_types.hpp"

namespace freefloat::sim {

// n actuated joints, k end-effectors; vectors [linear; angular] in the inertial frame.
struct GeneralizedJacobian {
  Eigen::MatrixXd Jstar;             // J* = Jm - J0E H0^-1 H0m (6k, n), eq 82: [v_E; w_E] per joint rate
  Eigen::MatrixXd J0;                // J0 = -H0^-1 H0m (6, n), eq 71: base CoM twist per joint rate
  Vec drift;                         // J0E H0^-1 M (6k,), eq 115: [v_E; w_E] at zero joint rates
  Vec6 base_twist = Vec6::Zero();    // H0^-1 M (6,): base CoM twist [v0; w0] at zero joint rates
};

}  // namespace freefloat::sim
