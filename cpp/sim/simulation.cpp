// The robot loop's factory (simulation.hpp): a Loop (loop.hpp) on the Pinocchio model of the
// Python model's arrays and its dynamics kernel (kernel/kernel.hpp), behind the interface the
// bindings and the batch use; the batch's lockstep of loops (lockstep.hpp) is made here too. The
// loop compiles in this unit only; its Pinocchio calls are pin_plant.hpp's (pin_plant.cpp), its
// tree's forward dynamics the kernel's (kernel/kernel.cpp). setup.py compiles the robot loop's
// units at -O1: its time is in the kernel's and libpinocchio_default's code, and -O1 ran every
// scene measured as fast as -O3 with Pinocchio's ABA (docs/bench.md, "The build").
#include <memory>
#include <stdexcept>
#include <utility>

#include "lockstep.hpp"
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
  ModelPtr tree = build_model(model);
  std::string refusal;
  std::unique_ptr<kernel::Kernel> kernel = kernel::Kernel::build(model, &refusal);
  auto loop = std::make_unique<Loop>(std::move(tree), std::move(kernel), std::move(refusal), std::move(joints), n_base,
                                     integrator, substeps, rtol, atol, control_period, start_time, record_every);
  for (int& id : ee_frames) id += 1;  // frame 0 is the universe
  loop->set_frames(base_frame + 1, std::move(ee_frames));
  return loop;
}

std::unique_ptr<Lockstep> make_lockstep(const std::vector<Simulation*>& sims, std::string* why) {
  std::string reason;
  std::vector<Loop*> loops;
  for (Simulation* s : sims) loops.push_back(dynamic_cast<Loop*>(s));
  if (loops.empty() || static_cast<int>(loops.size()) > LockstepLoops::kLanes)
    reason = "a lockstep takes 1 to " + std::to_string(LockstepLoops::kLanes) + " loops";
  for (const Loop* loop : loops) {
    if (!reason.empty()) break;
    if (loop == nullptr) reason = "a lockstep takes robot loops";
    else if (loop->tree_aba() != Simulation::TreeAba::kernel)
      reason = loop->kernel_ ? "the loop's tree_aba is Pinocchio's"
                             : "the dynamics kernel refuses the tree: " + loop->refusal_;
    else if (!loop->closed_.closures.empty()) reason = "the plant has loop closures";
    else if (!loop->integrator_->fixed_step()) reason = "integrator '" + loop->integrator_name_ + "' has no fixed step";
    else if (loop->integrator_name_ != loops[0]->integrator_name_ || loop->substeps_ != loops[0]->substeps_ ||
             loop->period_ != loops[0]->period_ || !same_structure(*loop->model_, *loops[0]->model_))
      reason = "the loops differ in their robot's joints, integrator or period";
  }
  if (!reason.empty()) {
    if (why != nullptr) *why = reason;
    return nullptr;
  }
  return std::make_unique<LockstepLoops>(std::move(loops));
}

}  // namespace freefloat::sim
