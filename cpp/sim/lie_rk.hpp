// The RKMK integrators of rkmk.hpp on a Pinocchio model's configuration space: its retraction is
// pinocchio::integrate, its chart is corrected on the free-flyer (se(3)) and planar (se(2)) joints.
#pragma once

#include <string>

#include "pin_plant.hpp"
#include "rkmk.hpp"

namespace freefloat::sim {

// The configuration space of `model`, which must outlive it.
inline ConfigurationSpace configuration_space(const Model& model) {
  return {nq(model), nv(model), chart_blocks(model),
          [&model](const Vec& q, const Vec& theta, Vec& out) { integrate(model, q, theta, out); }};
}

// One integrator of the registry by name on `model`'s configuration space (`model` outlives it).
class LieIntegrator : public RkmkIntegrator {
 public:
  LieIntegrator(const Model& model, const std::string& name, int substeps, double rtol, double atol)
      : RkmkIntegrator(configuration_space(model), name, substeps, rtol, atol) {}
};

}  // namespace freefloat::sim
