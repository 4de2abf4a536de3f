// generalized_jacobian.hpp's quantities of one state on a Pinocchio model (dissertation eqs 69-89,
// the same numbers as freefloat.dynamics.gjm.GJMState), from what pin_plant.hpp's
// centroidal_frames() takes from Pinocchio. Declaration: the definition is in
// pin_generalized_jacobian.cpp.
#pragma once

#include <vector>

#include "generalized_jacobian.hpp"
#include "pin_plant.hpp"

namespace freefloat::sim {

// At state (q, v): `base_frame` is the base CoM frame, `ee_frames` the end-effector frames (their
// origins are the points E), n the actuated joints (the last n velocities).
void generalized_jacobian(const Model& m, Workspace& w, const Vec& q, const Vec& v, int base_frame,
                          const std::vector<int>& ee_frames, int n, GeneralizedJacobian& out);

}  // namespace freefloat::sim
