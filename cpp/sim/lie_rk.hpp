// The RKMK integrators of rkmk.hpp on a Pinocchio model's configuration space: its retraction is
// pinocchio::integrate, its chart is corrected on the free-flyer (se(3)) and planar (se(2)) joints.
#pragma once

#include <pinocchio/algorithm/joint-configuration.hpp>

#include <string>
#include <vector>

#include "pin_model.hpp"
#include "rkmk.hpp"

namespace freefloat::sim {

// The configuration space of `model`, which must outlive it.
inline ConfigurationSpace configuration_space(const Model& model) {
  std::vector<ChartBlock> blocks;
  for (JointIndex j = 1; j < model.joints.size(); ++j) {
    const std::string kind = model.joints[j].shortname();
    if (kind == "JointModelFreeFlyer") blocks.push_back({model.joints[j].idx_v(), 6});
    if (kind == "JointModelPlanar") blocks.push_back({model.joints[j].idx_v(), 3});
  }
  return {model.nq, model.nv, std::move(blocks),
          [&model](const Vec& q, const Vec& theta, Vec& out) { pinocchio::integrate(model, q, theta, out); }};
}

// One integrator of the registry by name on `model`'s configuration space (`model` outlives it).
class LieIntegrator : public RkmkIntegrator {
 public:
  LieIntegrator(const Model& model, const std::string& name, int substeps, double rtol, double atol)
      : RkmkIntegrator(configuration_space(model), name, substeps, rtol, atol) {}
};

}  // namespace freefloat::sim
