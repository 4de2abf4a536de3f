// External wrenches on links with their time profiles (freefloat.dynamics.wrenches.ExternalWrench):
// on during [start, end), rising linearly over `rise` s, then constant; sampled at the start of
// each control period (zero-order hold), as WrenchProfiles.activate does.
#pragma once

#include <algorithm>
#include <vector>

#include "eigen_types.hpp"

namespace freefloat::sim {

// A wrench on the body of joint `joint`: inertial force (N) and torque (N m), the force acting at
// the link CoM `com` (in the joint frame, m).
struct Wrench {
  int joint;
  Vec3 com, force, torque;
};

struct WrenchProfile {
  Wrench full;                  // the wrench at profile value 1
  double start, end, rise;      // s

  // ExternalWrench.scale: 0 outside [start, end), a linear rise over `rise` s, then 1.
  double scale(double t) const {
    if (!(start <= t && t < end)) return 0.0;
    return rise <= 0.0 ? 1.0 : std::min(1.0, (t - start) / rise);
  }
};

// The wrenches `profiles` has on at time t, scaled (WrenchProfiles.activate, then active()).
inline void select_wrenches(const std::vector<WrenchProfile>& profiles, double t, std::vector<Wrench>& active) {
  active.clear();
  for (const WrenchProfile& p : profiles) {
    const double s = p.scale(t);
    if (s > 0.0) active.push_back({p.full.joint, p.full.com, s * p.full.force, s * p.full.torque});
  }
}

}  // namespace freefloat::sim
