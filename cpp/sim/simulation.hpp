// The compiled robot loop's interface (freefloat.dynamics._sim.Simulation), in Eigen and standard
// types only: the Python bindings (bindings/sim.cpp) and the batch (batch.hpp) see the loop
// through it without Pinocchio's headers, so that they compile in translation units of their own,
// beside the loop's (simulation.cpp, loop.hpp), each within a small share of the build's memory.
// make_simulation is defined in simulation.cpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "detumbling_law.hpp"
#include "eigen_types.hpp"
#include "generalized_jacobian.hpp"
#include "model_arrays.hpp"
#include "wrench_field.hpp"

namespace freefloat::sim {

// Where the actuated joint positions sit in q: plain coordinates (q index, position index) and
// continuous joints stored as (cos, sin) (q index of cos, position index).
struct JointMap {
  std::vector<int> scalar_q, scalar_pos, circle_q, circle_pos;
  int n = 0;

  void get(const Vec& q, Vec& out) const {
    for (size_t i = 0; i < scalar_q.size(); ++i) out[scalar_pos[i]] = q[scalar_q[i]];
    for (size_t i = 0; i < circle_q.size(); ++i) out[circle_pos[i]] = std::atan2(q[circle_q[i] + 1], q[circle_q[i]]);
  }
};

// q_d(t) = start + delta (10 s^3 - 15 s^4 + 6 s^5), s = t / T clipped to [0, 1].
struct Quintic {
  Vec start, delta;
  double duration;

  void at(double t, Vec& qd, Vec& qdd, Vec& qddd) const {
    const double T = duration, s = std::min(std::max(t / T, 0.0), 1.0);
    const double p = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    const double dp = 30.0 * s * s * (1.0 - s) * (1.0 - s) / T;
    const double ddp = 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) / (T * T);
    qd = start + p * delta;
    qdd = dp * delta;
    qddd = ddp * delta;
  }
};

// Telemetry arrays of one chunk (row-major, `rows` rows), filled in place; shapes as in
// freefloat.dynamics.telemetry.Telemetry.
struct Rows {
  int rows = 0;
  double *t, *q, *v, *tau, *joint_positions, *joint_reference, *base_position, *base_quaternion, *base_twist,
      *ee_position, *ee_quaternion, *com, *momentum, *energy, *work;
};

// One loop closure (closure.Closure): frame 1 = placement1 in joint1's frame, frame 2 = placement2
// in joint2's frame (joints by Pinocchio index, 0 the universe); rotation_rows: the stopped rows
// of the relative angular velocity in frame 1's axes (0, 1, 2: x, y, z).
struct ClosureSpec {
  int joint1 = 0, joint2 = 0;
  Pose placement1 = Pose::Identity(), placement2 = Pose::Identity();
  std::vector<int> rotation_rows;

  int size() const { return 3 + static_cast<int>(rotation_rows.size()); }
};

// The constrained dynamics at one state (closures.solve): accelerations a (nv,), closure forces
// lambda (m,) and residual e (m,), the closures' rows stacked in order (each the position of frame
// 2 from frame 1 in frame 1's axes, then its rotation rows), and the rank of the Delassus matrix.
struct ClosureSolution {
  Vec a, force, e;
  int rank = 0;
};

// The two-hand detumbling law's settings (LoopDetumblingController): task rows into the 6k rows
// [v_E; w_E], mission joints, gains and limits, the grasp weld, the target's CoM frame and inertia
// and the first hand's frame.
struct LoopDetumblingSettings {
  std::vector<int> rows, joints;
  double kd = 0.0, period = 0.0, baumgarte = 0.0, squeeze = 0.0, limit = 0.0;  // 1/s, s, 1/s, N, N m (0: none)
  ClosureSpec grasp;               // the weld between the second hand (frame 1) and its grasp on the target
  int target_joint = 0, first_joint = 0;  // Pinocchio joint indices
  // The target's CoM frame in target_joint's frame, the first hand's frame in first_joint's frame.
  Pose target_placement = Pose::Identity(), first_placement = Pose::Identity();
  double mass = 0.0;               // kg
  Vec3 inertia = Vec3::Zero();     // principal moments, target frame axes, kg m^2
};

// The two-hand law's state, carried from period to period and handed back to Python.
struct LoopDetumblingState {
  std::optional<Vec> previous;           // qdot_d of the previous period (n,)
  // The closure force lambda of the previous period (LoopDetumblingController._shared_force):
  // [force (N); torque about the grasp point (N m)] in the second hand's axes.
  Vec6 force = Vec6::Zero();
  std::vector<double> times, residuals;  // LoopLog.t, LoopLog.rows_residual since last taken
  std::vector<bool> saturated;           // LoopLog.saturated
};

// The loop: zero-order-hold control periods of a plant (ABA, or the constrained dynamics with loop
// closures), an integrator, a control law, and telemetry rows. Vectors q (nq,), v (nv,) in
// Pinocchio's order; joint vectors (n,) over the actuated joints (the last n velocities).
class Simulation {
 public:
  enum class Convention { local, world };  // Pinocchio's, of the plant's ABA and the law's CRBA

  virtual ~Simulation() = default;

  // A new run on the same model and Data (see loop.hpp).
  virtual void configure(const std::string& integrator, int substeps, double rtol, double atol,
                         double control_period, double start_time, int record_every) = 0;
  // The plant's numbers from `model`, which must have this loop's joints and frames.
  virtual void set_model(const ModelArrays& model) = 0;
  // The model the computed-torque and detumbling laws compute on, until the next configure().
  virtual void set_law_model(const ModelArrays& model) = 0;
  virtual void set_convention(Convention convention) = 0;
  virtual Convention convention() const = 0;
  // The tree's forward dynamics: freefloat's kernel (kernel/kernel.hpp) or Pinocchio's ABA; the
  // kernel where the tree has only joints it has (kernel_refusal() empty), unless set otherwise.
  enum class TreeAba { kernel, pinocchio };
  virtual void set_tree_aba(TreeAba aba) = 0;  // std::invalid_argument: kernel_refusal() for a tree it refuses
  virtual TreeAba tree_aba() const = 0;
  virtual const std::string& kernel_refusal() const = 0;  // why the kernel refuses the tree (empty: it does not)

  virtual void set_computed_torque(Quintic reference, double kp, double kd) = 0;
  virtual void set_detumbling(DetumblingLaw law) = 0;
  // The detumbling law with its state (held posture, previous rates, residuals), if set.
  virtual DetumblingLaw* detumbling() = 0;
  virtual void set_closures(const std::vector<ClosureSpec>& closures, double baumgarte) = 0;
  // The constrained dynamics at (q, v, tau) outside of any run.
  virtual ClosureSolution closure_solve(const Vec& q, const Vec& v, const Vec& tau) = 0;
  virtual void set_loop_detumbling(const LoopDetumblingSettings& settings, LoopDetumblingState state) = 0;
  virtual bool has_loop_detumbling() const = 0;
  // The two-hand law's torques (n,) at time t and (q, v), outside of any run (its state advances).
  virtual Vec loop_detumbling_torque(double t, const Vec& q, const Vec& v) = 0;
  // The two-hand law's state; its log since the last call is taken (cleared).
  virtual LoopDetumblingState take_loop_detumbling_state() = 0;
  virtual void set_wrenches(std::vector<Wrench> wrenches) = 0;
  virtual void set_wrench_profiles(std::vector<WrenchProfile> profiles) = 0;
  virtual void hold(const Vec& tau) = 0;

  virtual void step_period() = 0;
  virtual void set_state(const Vec& q, const Vec& v, long period, double work) = 0;
  virtual void restart(const Vec& q, const Vec& v) = 0;
  virtual bool has_law_state() const = 0;
  virtual void set_bodies(const double* bodies) = 0;
  virtual void set_reference(const Vec& start, const Vec& delta) = 0;
  virtual bool has_reference() const = 0;
  virtual int run(long last, Rows& out, int row, std::string& error) = 0;
  virtual void record_now(Rows& out, int row, const Vec* reference) = 0;

  virtual Vec acceleration(const Vec& q, const Vec& v, const Vec& tau) = 0;
  // Seconds per acceleration() of the plant's ABA in C++ (this thread's CPU time), mean of `calls`
  // calls at one state.
  virtual double time_acceleration(const Vec& q, const Vec& v, const Vec& tau, long calls) = 0;
  virtual GeneralizedJacobian generalized_jacobian_at(const Vec& q, const Vec& v) = 0;

  virtual const Vec& q() const = 0;
  virtual const Vec& v() const = 0;
  virtual long period() const = 0;
  virtual double time() const = 0;  // of the current period, s
  virtual double work() const = 0;
  virtual long evaluations() const = 0;
  virtual int nq() const = 0;
  virtual int nv() const = 0;
  virtual int njoints() const = 0;  // Pinocchio's, with the universe
  virtual int n_joints() const = 0;  // the actuated joints
};

// One lane of a Lockstep: whether it runs (its loop set for a run), the chunk its loop writes rows
// into and its next free row; what Lockstep::run leaves: the loop's blow-up message or the text of
// an error it threw (empty: none), and whether it stopped at a period that records with no free row.
struct LaneChunk {
  bool active = false;
  Rows rows;
  int row = 0;
  std::string blow_up, failure;
  bool full = false;
};

// Loops of one robot advanced period by period together (batch.hpp): the integrator's stages of
// every lane evaluated at once in the dynamics kernel's lanes, each lane's law, wrenches,
// telemetry, checks and work its own loop's; each lane's numbers are its loop's run alone to
// round-off.
class Lockstep {
 public:
  virtual ~Lockstep() = default;
  virtual int lanes() const = 0;
  // The bodies of lane `lane`'s plant for its next run (as Simulation::set_bodies'), after its
  // loop's set_bodies().
  virtual void set_bodies(int lane, const double* bodies) = 0;
  // Advances each active lane whose loop has not reached period `last` (exclusive), for up to
  // `periods` periods, until its loop blows up or finds no free row for a period that records.
  virtual void run(long last, long periods, LaneChunk* lanes) = 0;
};

// The lockstep of `loops` (up to the kernel's lanes, of one robot, made by make_simulation), or
// null and why not in `why`: each must have the dynamics kernel (tree_aba kernel), a fixed-step
// integrator and no loop closures.
std::unique_ptr<Lockstep> make_lockstep(const std::vector<Simulation*>& loops, std::string* why);

// A loop on the model of `model` (ValueError-style std::invalid_argument on a bad one), with its
// integrator's settings, control period (s), start time (s), recording rate, and the base CoM and
// end-effector frames (indices into the model's frames, universe excluded).
std::unique_ptr<Simulation> make_simulation(const ModelArrays& model, JointMap joints, int n_base,
                                            const std::string& integrator, int substeps, double rtol, double atol,
                                            double control_period, double start_time, int record_every,
                                            int base_frame, std::vector<int> ee_frames);

// The version of the libpinocchio the loop is compiled and linked against.
const char* pinocchio_version();

}  // namespace freefloat::sim
