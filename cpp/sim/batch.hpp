// Many runs of one scene in one call, on C++ threads: each thread drives a loop of its own
// (simulation.hpp, with its own Pinocchio Data) through runs it takes in turn, each from its initial
// state (and, under computed torque, its own quintic), writing the run's telemetry rows into a
// free slot of one shared block of rows; or, in lockstep, a group of loops (a Lockstep), each lane
// taking the next run as soon as its own ends. The caller waits without Python's lock, takes the
// runs as they finish and frees their slots; a stop request ends every run at its next slice of
// periods. No thread touches Python, nor words a run's status: each run reports what ended it (the
// loop's blow-up message, or the text of an error it threw), which Python words as
// simulation.run does (freefloat.dynamics.simulation.ended_by).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "simulation.hpp"

namespace freefloat::sim {

class Batch {
 public:
  // Periods a run does between two looks at the stop request (a few ms at nv 22).
  static constexpr long kSlice = 1000;

  // A finished run: its index, the slot holding its rows, rows written, periods done, dynamics
  // evaluations, loop wall time (s), and what ended it early, if anything: the loop's blow-up
  // message (Simulation::run's), or the text of an error the loop threw (e.g. Pinocchio refusing a
  // degenerate state).
  struct Done {
    int run, slot, rows;
    long periods, evaluations;
    double wall;
    std::optional<std::string> blow_up, failure;
  };

  // The runs' inputs, row-major: q0 (runs, nq), v0 (runs, nv), for a computed-torque law the
  // quintics' start and delta (runs, n) (null without one), and each run's plant bodies (runs,
  // njoints - 1, 13: see Simulation::set_bodies; null: the loops' own). `rows` holds `slots` slots
  // of `rows_per_run` rows each. With `lanes` above 1, the loops run in lockstep groups of `lanes`
  // (make_lockstep; std::invalid_argument saying why when they cannot), one thread per group. The
  // loops must outlive the batch.
  Batch(std::vector<Simulation*> loops, int lanes, int runs, long last, const double* q0, const double* v0,
        const double* start, const double* delta, const double* bodies, Rows rows, int rows_per_run, int slots)
      : loops_(std::move(loops)), runs_(runs), last_(last), q0_(q0), v0_(v0), start_(start), delta_(delta),
        bodies_(bodies), rows_(rows), per_run_(rows_per_run) {
    if (lanes < 1) throw std::invalid_argument("lanes must be >= 1");
    for (size_t first = 0; lanes > 1 && first < loops_.size(); first += lanes) {
      std::vector<Simulation*> group(loops_.begin() + first, loops_.begin() + std::min(loops_.size(), first + lanes));
      std::string why;
      std::unique_ptr<Lockstep> lockstep = make_lockstep(group, &why);
      if (!lockstep) throw std::invalid_argument("these runs cannot run in lockstep: " + why);
      groups_.push_back(std::move(group));
      locksteps_.push_back(std::move(lockstep));
    }
    for (Simulation* s : loops_) {
      if (s->has_law_state()) throw std::invalid_argument("a detumbling law keeps a state: its runs cannot share a loop");
      if ((start_ != nullptr) != s->has_reference())
        throw std::invalid_argument("the quintics' start and delta go with a computed-torque law, and only with one");
    }
    if (slots < 1 || static_cast<long>(slots) * per_run_ > rows_.rows) throw std::invalid_argument("slots out of range");
    for (int i = 0; i < slots; ++i) free_.push_back(i);
    in_use_.assign(slots, false);
    running_ = static_cast<int>(locksteps_.empty() ? loops_.size() : locksteps_.size());
    try {
      if (locksteps_.empty())
        for (Simulation* s : loops_) threads_.emplace_back([this, s] { work(*s); });
      for (size_t g = 0; g < locksteps_.size(); ++g) threads_.emplace_back([this, g] { work_lockstep(g); });
    } catch (...) {  // a thread could not start: stop those that did (the destructor will not run)
      stop();
      for (std::thread& t : threads_) t.join();
      throw;
    }
  }

  ~Batch() {
    stop();
    for (std::thread& t : threads_) t.join();
  }

  // Wait up to `seconds` for a run to finish or every thread to end; true when they have ended.
  bool wait(double seconds) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return running_ == 0 || !done_.empty(); });
    return running_ == 0;
  }

  // The runs finished since the last call.
  std::vector<Done> take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Done> out(done_.begin(), done_.end());
    done_.clear();
    return out;
  }

  // The slot's rows are read: a next run may write there.
  void release(int slot) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (slot < 0 || slot >= static_cast<int>(in_use_.size()) || !in_use_[slot])
        throw std::invalid_argument("release: slot " + std::to_string(slot) + " holds no finished run");
      in_use_[slot] = false;
      free_.push_back(slot);
    }
    changed_.notify_all();
  }

  // Every run stops at its next slice (its rows so far kept); no run starts.
  void stop() {
    stopping_ = true;
    changed_.notify_all();
  }

 private:
  // A run in progress on a loop: what it reports when done, and where it started.
  struct Started {
    Done d;
    std::chrono::steady_clock::time_point begin;
    long evaluations;
    Rows rows;  // its slot's rows (rows: the slot's end)
    int first;  // its slot's first row
  };

  // Run `run` set up on `sim` in a free slot (false when stopped first): its bodies, initial state
  // and quintic; `lockstep` given its bodies too.
  bool start_run(Simulation& sim, int run, Started& s, Lockstep* lockstep = nullptr, int lane = 0) {
    const int slot = take_slot();
    if (slot < 0) return false;
    const int nq = sim.nq(), nv = sim.nv(), n = sim.n_joints();
    s.d = Done{run, slot, 0, 0, 0, 0.0, std::nullopt, std::nullopt};
    s.begin = std::chrono::steady_clock::now();
    s.evaluations = sim.evaluations();
    s.rows = rows_;
    s.rows.rows = (slot + 1) * per_run_;
    s.first = slot * per_run_;
    guarded(s.d, [&] {
      if (bodies_ != nullptr) {
        const double* bodies = bodies_ + 13L * (sim.njoints() - 1) * run;
        sim.set_bodies(bodies);
        if (lockstep != nullptr) lockstep->set_bodies(lane, bodies);
      }
      sim.restart(Eigen::Map<const Vec>(q0_ + static_cast<long>(nq) * run, nq),
                  Eigen::Map<const Vec>(v0_ + static_cast<long>(nv) * run, nv));
      if (start_ != nullptr)
        sim.set_reference(Eigen::Map<const Vec>(start_ + static_cast<long>(n) * run, n),
                          Eigen::Map<const Vec>(delta_ + static_cast<long>(n) * run, n));
    });
    return true;
  }

  // The run on `sim` is over: its last row (when it completed), its counts, handed to the caller.
  void finish_run(Simulation& sim, Started& s) {
    Done& d = s.d;
    if (!d.blow_up && !d.failure && sim.period() == last_)
      guarded(d, [&] { sim.record_now(s.rows, s.first + d.rows++, nullptr); });
    d.periods = sim.period();
    d.evaluations = sim.evaluations() - s.evaluations;
    d.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - s.begin).count();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_.push_back(std::move(d));
    }
    changed_.notify_all();
  }

  // `work()` on the run of `d`; the text of an error it throws in d.failure.
  template <typename Work>
  static void guarded(Done& d, Work&& work) {
    try {
      work();
    } catch (const std::exception& e) {
      d.failure = e.what();
    }
  }

  void work(Simulation& sim) {
    Started s;
    for (int run; !stopping_ && (run = next_++) < runs_;) {
      if (!start_run(sim, run, s)) break;
      Done& d = s.d;
      std::string blow_up;
      if (!d.failure)
        guarded(d, [&] {
          while (sim.period() < last_ && blow_up.empty() && !stopping_) {
            const long before = sim.period();
            d.rows += sim.run(std::min(last_, before + kSlice), s.rows, s.first + d.rows, blow_up);
            if (sim.period() == before && blow_up.empty())
              throw std::logic_error("the loop made no progress (its rows are full)");
          }
          if (!blow_up.empty()) d.blow_up = blow_up;
        });
      finish_run(sim, s);
    }
    ended();
  }

  // A lockstep group's thread: each lane takes the next run when its own has ended.
  void work_lockstep(size_t group) {
    Lockstep& lockstep = *locksteps_[group];
    const std::vector<Simulation*>& sims = groups_[group];
    const int lanes = lockstep.lanes();
    std::vector<Started> started(lanes);
    std::vector<LaneChunk> chunks(lanes);
    for (bool more = true;;) {
      for (int l = 0; l < lanes; ++l) {
        while (more && !chunks[l].active) {
          const int run = stopping_ ? runs_ : next_++;
          more = run < runs_ && start_run(*sims[l], run, started[l], &lockstep, l);
          if (!more) break;
          if (!started[l].d.failure) chunks[l] = LaneChunk{true, started[l].rows, started[l].first, {}, {}, false};
          else finish_run(*sims[l], started[l]);  // its set-up failed: the lane takes the next run
        }
      }
      bool any = false;
      for (const LaneChunk& c : chunks) any |= c.active;
      if (!any) break;
      lockstep.run(last_, kSlice, chunks.data());
      for (int l = 0; l < lanes; ++l) {
        LaneChunk& c = chunks[l];
        Simulation& sim = *sims[l];
        if (!c.active) continue;
        Done& d = started[l].d;
        d.rows = c.row - started[l].first;
        if (c.full && c.blow_up.empty() && c.failure.empty()) c.failure = "the loop made no progress (its rows are full)";
        if (c.blow_up.empty() && c.failure.empty() && sim.period() < last_ && !stopping_) continue;
        if (!c.blow_up.empty()) d.blow_up = c.blow_up;
        if (!c.failure.empty()) d.failure = c.failure;
        c.active = false;
        finish_run(sim, started[l]);
      }
    }
    ended();
  }

  // This thread has ended.
  void ended() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --running_;
    }
    changed_.notify_all();
  }

  // A free slot, waiting for one; -1 when stopped first.
  int take_slot() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return stopping_ || !free_.empty(); });
    if (stopping_) return -1;
    const int slot = free_.front();
    free_.pop_front();
    in_use_[slot] = true;
    return slot;
  }

  std::vector<Simulation*> loops_;
  std::vector<std::vector<Simulation*>> groups_;  // the lockstep groups of loops_ (none: one thread per loop)
  std::vector<std::unique_ptr<Lockstep>> locksteps_;
  int runs_;
  long last_;
  const double *q0_, *v0_, *start_, *delta_, *bodies_;
  Rows rows_;
  int per_run_;
  std::atomic<int> next_{0};
  std::atomic<bool> stopping_{false};
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<int> free_;
  std::vector<bool> in_use_;  // by a run, or by its rows until released
  std::deque<Done> done_;
  int running_ = 0;
  std::vector<std::thread> threads_;
};

}  // namespace freefloat::sim
