// The robot loop's factory (simulation.hpp): a Loop (loop.hpp) on the Pinocchio model of the
// Python model's arrays, behind the interface the bindings and the batch use. The loop compiles in
// this unit only; its Pinocchio calls are pin_plant.hpp's (pin_plant.cpp). setup.py compiles the
// robot loop's units at -O1: its time is in libpinocchio_default's algorithms, and -O1 ran every
// scene measured as fast as -O3 (docs/bench.md, "The build").
#include <memory>
#include <stdexcept>
#include <utility>

#include "loop.hpp"
#include "simulation.hpp"

namespace freefloat::sim {

std::unique_ptr<Simulation> make_simulation(const ModelArrays& model, JointMap joints, int n_base,
                                            const std::string& integrator, int substeps, double rtol, double atol,
                                            double control_period, double start_time, int record_every,
                                            int base_frame, std::vector<int> ee_frames) {
  if (record_every < 1) throw std::invalid_argument("record_every must be >= 1");
  const int frames = static_cast<int>(model.frame_parent.size());
  for (int id : ee_frames)
    if (id < 0 || id >= frames) throw std::invalid_argument("ee frame index out of range");
  if (base_frame < 0 || base_frame >= frames) throw std::invalid_argument("base frame index out of range");
  auto loop = std::make_unique<Loop>(build_model(model), std::move(joints), n_base, integrator, substeps, rtol, atol,
                                     control_period, start_time, record_every);
  for (int& id : ee_frames) id += 1;  // frame 0 is the universe
  loop->set_frames(base_frame + 1, std::move(ee_frames));
  return loop;
}

}  // namespace freefloat::sim
