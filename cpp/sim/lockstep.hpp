// Loops of one robot advanced together (simulation.hpp's Lockstep, for batch.hpp): each period,
// every lane's law, wrenches and telemetry row by its own loop, then one fixed-step integration of
// all lanes whose every stage evaluates the lanes' dynamics at once in the dynamics kernel
// (Kernel::aba_lanes), then each loop's checks and work. A lane whose run has ended (or that has
// none) is left out; the kernel's spare lanes evaluate a copy of a running lane's state.
// Compiled with the loop (sim/simulation.cpp).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kernel/kernel.hpp"
#include "lie_rk.hpp"
#include "loop.hpp"
#include "simulation.hpp"

namespace freefloat::sim {

class LockstepLoops final : public Lockstep {
 public:
  static constexpr int kLanes = kernel::Kernel::kLanes;

  // `loops`: up to kLanes loops of one robot, each with the kernel, configured alike with a
  // fixed-step integrator (make_lockstep checks).
  explicit LockstepLoops(std::vector<Loop*> loops)
      : loops_(std::move(loops)), kernel_(loops_[0]->kernel_->clone()),
        integrator_(configuration_space(*loops_[0]->model_), loops_[0]->integrator_name_, loops_[0]->substeps_, 1e-10,
                    1e-12, 100000, kLanes) {
    for (Vec& a : spare_) a.resize(loops_[0]->nv());
    dynamics_ = [this](const Vec* const* q, const Vec* const* v, Vec* const* a, int n) { evaluate(q, v, a, n); };
  }

  int lanes() const override { return static_cast<int>(loops_.size()); }

  void set_bodies(int lane, const double* bodies) override { kernel_->set_lane_bodies(lane, bodies); }

  void run(long last, long periods, LaneChunk* chunks) override {
    for (long p = 0; p < periods; ++p) {
      int n = 0;
      for (int l = 0; l < lanes(); ++l) {
        LaneChunk& c = chunks[l];
        Loop& loop = *loops_[l];
        if (!c.active || !c.blow_up.empty() || !c.failure.empty() || c.full || loop.k_ >= last) continue;
        const double t = loop.start_ + loop.k_ * loop.period_;
        const bool records = loop.k_ % loop.record_every_ == 0;
        if (records && c.row == c.rows.rows) {
          c.full = true;
          continue;
        }
        if (!attempt(c, [&] { loop.begin_period(t, records, c.rows, c.row); })) continue;
        loop.qn_ = loop.q_;
        loop.vn_ = loop.v_;
        lane_[n] = l;
        time_[n] = t;
        q_[n] = &loop.qn_;
        v_[n] = &loop.vn_;
        ++n;
      }
      if (n == 0) return;
      const long before = integrator_.evaluations();
      try {
        integrator_.advance_lanes(dynamics_, q_, v_, n, loops_[lane_[0]]->period_);
      } catch (const std::exception& e) {  // none expected: the kernel and the retraction do not throw
        for (int i = 0; i < n; ++i) chunks[lane_[i]].failure = e.what();
        continue;
      }
      for (int i = 0; i < n; ++i) {
        Loop& loop = *loops_[lane_[i]];
        loop.lockstep_evaluations_ += integrator_.evaluations() - before;
        attempt(chunks[lane_[i]], [&] { loop.end_step(time_[i]); });
      }
    }
  }

 private:
  // `work()` on lane `c`'s loop; false when it throws: a blow-up's message (std::overflow_error,
  // as Loop::run reports it) in c.blow_up, any other error's text in c.failure (as Batch's).
  template <typename Work>
  static bool attempt(LaneChunk& c, Work&& work) {
    try {
      work();
      return true;
    } catch (const std::overflow_error& e) {
      c.blow_up = e.what();
    } catch (const std::exception& e) {
      c.failure = e.what();
    }
    return false;
  }

  // The accelerations a[i] of the n states (q[i], v[i]) of lanes lane_[0..n), each under its
  // loop's held torques and wrenches, in the kernel's lanes of the same index.
  void evaluate(const Vec* const* q, const Vec* const* v, Vec* const* a, int n) {
    const double *qs[kLanes], *vs[kLanes], *taus[kLanes];
    double* as[kLanes];
    kernel::Wrenches wrenches[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      qs[l] = q[0]->data();
      vs[l] = v[0]->data();
      taus[l] = loops_[lane_[0]]->tau_full_.data();
      as[l] = spare_[l].data();
    }
    for (int i = 0; i < n; ++i) {
      const int l = lane_[i];
      Loop& loop = *loops_[l];
      a[i]->resize(loop.nv());
      qs[l] = q[i]->data();
      vs[l] = v[i]->data();
      taus[l] = loop.tau_full_.data();
      as[l] = a[i]->data();
      wrenches[l] = loop.held_wrenches();
    }
    kernel_->aba_lanes(qs, vs, taus, wrenches, as);
  }

  std::vector<Loop*> loops_;
  std::unique_ptr<kernel::Kernel> kernel_;  // the loops' tree, each lane with its plant's bodies
  RkmkIntegrator integrator_;
  LaneDynamics dynamics_;
  // This period's running lanes: their index, time, and end state (their loops' qn_, vn_).
  int lane_[kLanes] = {};
  double time_[kLanes] = {};
  Vec* q_[kLanes] = {};
  Vec* v_[kLanes] = {};
  Vec spare_[kLanes];  // the accelerations of spare lanes
};

}  // namespace freefloat::sim
