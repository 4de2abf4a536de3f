// A robot's model as the arrays that describe a Python-side pin.Model (no object is shared across
// the two bindings), from which pin_model.hpp rebuilds it in C++.
#pragma once

#include <string>
#include <vector>

namespace freefloat::sim {

// Joints 1..n of the Python model: parent[j], kind[j] (Pinocchio's joint kind), name[j], subspace
// (n, 6) [linear; angular], placement (n, 4, 4) row-major, inertia mass (n,), lever (n, 3) (CoM in
// the joint frame), rotational inertia about the CoM (n, 3, 3); armature (armature_size: nv
// expected), gravity (3,), frames: parent joint (f,), placement (f, 4, 4).
struct ModelArrays {
  std::vector<int> parent;
  std::vector<std::string> kind, name;
  const double *subspace, *placement, *mass, *lever, *rotational;
  const double* armature;
  long armature_size;
  const double* gravity;
  std::vector<int> frame_parent;
  const double* frame_placement;
};

}  // namespace freefloat::sim
