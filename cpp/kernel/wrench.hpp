// An external wrench on one body, as the dynamics kernel takes it (plain numbers, no Eigen).
#pragma once

namespace freefloat::kernel {

// A force `force` acting at `point` (in the body's joint frame, m) and a torque `torque`, on the
// body of Pinocchio joint `joint` (>= 1); both in world axes when `world`, else in the joint
// frame's axes (Pinocchio's fext: `point` zero, the torque about the joint origin). N, N m.
struct Wrench {
  int joint = 0;
  bool world = true;
  double point[3] = {0.0, 0.0, 0.0};
  double force[3] = {0.0, 0.0, 0.0};
  double torque[3] = {0.0, 0.0, 0.0};
};

// The wrenches of one state: `count` of them from `first`.
struct Wrenches {
  const Wrench* first = nullptr;
  int count = 0;
};

}  // namespace freefloat::kernel
