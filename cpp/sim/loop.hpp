// The simulation loop of freefloat.dynamics.simulation.run in C++: zero-order-hold control
// periods, the dynamics kernel (kernel/kernel.hpp) or Pinocchio's ABA as the plant with the
// external wrenches of wrench_field.hpp, an integrator of lie_rk.hpp, a control law with the exact
// H* and c* (the joint-space computed torque of freefloat.space.control, eqs 136-137, on a quintic
// reference, the detumbling law of detumbling_law.hpp, or the two-hand law of
// loop_detumbling_law.hpp), and the telemetry row of simulation.Recorder. With loop closures (closures.hpp) the plant is the constrained dynamics of
// closures.ClosedModel instead of ABA.
// Pinocchio is called through pin_plant.hpp, whose definitions compile in a unit of their own.
#pragma once

#include <Eigen/Geometry>  // the telemetry's quaternions

#include <time.h>

#include <cstdio>
#include <memory>
#include <optional>

#include "closures.hpp"
#include "detumbling_law.hpp"
#include "kernel/kernel.hpp"
#include "lie_rk.hpp"
#include "loop_detumbling_law.hpp"
#include "periods.hpp"
#include "pin_generalized_jacobian.hpp"
#include "pin_plant.hpp"
#include "simulation.hpp"
#include "wrench_field.hpp"

namespace freefloat::sim {

class LockstepLoops;  // lockstep.hpp: advances loops together, through their periods' parts

// The loop of simulation.hpp's interface on a Pinocchio model (compiled in simulation.cpp only).
// The integrator refers to *model_, whose address never changes (set_model() replaces its numbers).
// The tree's forward dynamics are the kernel's (`kernel`, null when it refuses the tree: `refusal`
// says why) or Pinocchio's ABA (set_tree_aba); with loop closures, Pinocchio's constrained dynamics.
class Loop final : public Simulation {
 public:
  static constexpr double kMaxSpeed = 1e6, kMaxPosition = 1e12;  // simulation.MAX_SPEED, MAX_POSITION

  Loop(ModelPtr model, std::unique_ptr<kernel::Kernel> kernel, std::string refusal, JointMap joints, int n_base,
       const std::string& integrator, int substeps, double rtol, double atol, double control_period,
       double start_time, int record_every)
      : model_(std::move(model)), data_(make_workspace(*model_)), record_data_(copy_workspace(*data_)),
        kernel_(std::move(kernel)), refusal_(std::move(refusal)), joints_(std::move(joints)), nb_(n_base) {
    qn_.resize(this->nq());
    vn_.resize(this->nv());
    aba_ = kernel_ ? TreeAba::kernel : TreeAba::pinocchio;
    refresh_numbers();
    configure(integrator, substeps, rtol, atol, control_period, start_time, record_every);
    dynamics_ = [this](const Vec& q, const Vec& v, Vec& a) {
      const bool with_wrenches = !wrenches_.empty();
      if (closed_.empty() && aba_ == TreeAba::kernel) return kernel_aba(q, v, tau_full_, a);
      if (with_wrenches) freefloat::sim::set_wrenches(*model_, *data_, q, wrenches_);
      if (!closed_.empty()) return closed_.solve(*model_, *data_, q, v, tau_full_, with_wrenches, a);
      aba(*model_, *data_, q, v, tau_full_, with_wrenches, world(), a);
    };
  }

  // A new run on the same model and Data: the integrator and its settings, the period, the start
  // time and the recording rate; no law, no torques, no wrenches, no work, period 0, the neutral
  // state, evaluations counted from zero. Everything a run leaves behind is reset here, so a loop
  // reused after a finished, failed or interrupted run starts as a new one does.
  void configure(const std::string& integrator, int substeps, double rtol, double atol, double control_period,
                 double start_time, int record_every) override {
    { const LieIntegrator check(*model_, integrator, substeps, rtol, atol); }  // throws first, nothing changed
    integrator_.emplace(*model_, integrator, substeps, rtol, atol);
    integrator_name_ = integrator;
    substeps_ = substeps;
    period_ = control_period;
    start_ = start_time;
    record_every_ = record_every;
    reference_.reset();
    detumbling_.reset();
    loop_law_.reset();
    law_model_.reset();  // its Data stay for the next set_law_model()
    closed_.closures.clear();
    closed_.forget();
    controlled_ = false;
    wrenches_.clear();
    profiles_.clear();
    kp_ = kd_ = work_ = 0.0;
    k_ = 0;
    lockstep_evaluations_ = 0;
    q_ = neutral(*model_);
    v_ = Vec::Zero(this->nv());
    tau_full_ = Vec::Zero(this->nv());
    tau_ = Vec::Zero(joints_.n);
    pos_ = Vec::Zero(joints_.n);
  }

  // The plant's numbers (inertias, placements, armature, gravity, frame placements) from `arrays`,
  // a model of this loop's structure (same_structure): its Data serve it unchanged.
  void set_model(const ModelArrays& arrays) override {
    ModelPtr model = model_like_this(arrays, "set_model");
    if (kernel_) kernel_->set_numbers(arrays);
    replace(*model_, std::move(model));
    closed_.forget();
    refresh_numbers();
  }

  // The model the computed-torque and detumbling laws compute H*, c* and the generalized Jacobian
  // on, when it is not the plant's: a controller that keeps the nominal robot while the plant has
  // other numbers (a batch's varied masses), of this loop's structure; until the next
  // configure(). Its Data are made once and kept, as set_model() keeps the plant's.
  void set_law_model(const ModelArrays& arrays) override {
    law_model_ = model_like_this(arrays, "set_law_model");
    if (!law_data_) law_data_ = make_workspace(*law_model_);
  }

  // Pinocchio's convention for ABA and CRBA (the same numbers to round-off; WORLD or LOCAL is
  // the faster one depending on the tree, see compiled.CONVENTION_NV). Kept across configure().
  void set_convention(Convention convention) override { convention_ = convention; }
  Convention convention() const override { return convention_; }

  // The tree's forward dynamics (kept across configure(), as the convention).
  void set_tree_aba(TreeAba aba) override {
    if (aba == TreeAba::kernel && !kernel_) throw std::invalid_argument(refusal_);
    aba_ = aba;
  }
  TreeAba tree_aba() const override { return aba_; }
  const std::string& kernel_refusal() const override { return refusal_; }

  void set_frames(int base_frame, std::vector<int> ee_frames) {
    base_frame_ = base_frame;
    ee_frames_ = std::move(ee_frames);
  }

  void set_computed_torque(Quintic reference, double kp, double kd) override {
    controlled_ = true;
    reference_ = std::move(reference);
    kp_ = kp;
    kd_ = kd;
  }

  void set_detumbling(DetumblingLaw law) override {
    controlled_ = true;
    detumbling_ = std::move(law);
  }
  DetumblingLaw* detumbling() override { return detumbling_ ? &*detumbling_ : nullptr; }

  // The plant's loop closures and Baumgarte rate (none: ABA, the exact tree).
  void set_closures(const std::vector<ClosureSpec>& closures, double baumgarte) override {
    std::vector<ClosureSpec> checked;  // all or nothing: a bad closure leaves the plant as it was
    for (const ClosureSpec& c : closures) checked.push_back(check_closure(c));
    closed_.closures = std::move(checked);
    closed_.baumgarte = baumgarte;
    closed_.forget();
  }

  ClosureSolution closure_solve(const Vec& q, const Vec& v, const Vec& tau) override {
    ClosureSolution out;
    closed_.solve(*model_, *data_, q, v, tau, false, out.a);
    out.force = closed_.force;
    out.e = closed_.rows.e;
    out.rank = closed_.rank;
    return out;
  }

  void set_loop_detumbling(const LoopDetumblingSettings& settings, LoopDetumblingState state) override {
    check_joint(settings.target_joint, "frame joint");
    check_joint(settings.first_joint, "frame joint");
    check_closure(settings.grasp);
    controlled_ = true;
    loop_law_.emplace(settings, std::move(state));
  }
  bool has_loop_detumbling() const override { return loop_law_.has_value(); }

  Vec loop_detumbling_torque(double t, const Vec& q, const Vec& v) override {
    Vec tau(joints_.n);
    loop_law_torque(t, q, v, tau);
    return tau;
  }

  LoopDetumblingState take_loop_detumbling_state() override {
    LoopDetumblingState& state = *loop_law_;
    LoopDetumblingState taken = state;
    state.times.clear();
    state.residuals.clear();
    state.saturated.clear();
    return taken;
  }

  // Wrenches held over the next periods (already scaled by their profile); empty: none.
  void set_wrenches(std::vector<Wrench> wrenches) override { wrenches_ = std::move(wrenches); }

  // Wrenches with profiles, selected by run() at the start of each period (replaces set_wrenches).
  void set_wrench_profiles(std::vector<WrenchProfile> profiles) override { profiles_ = std::move(profiles); }

  // Hold the joint torques `tau` (n,) from the current period on (a controller outside the loop).
  void hold(const Vec& tau) override {
    tau_ = tau;
    tau_full_.tail(joints_.n) = tau;
    controlled_ = true;
  }

  // One control period from the current state, torques and wrenches held. Throws
  // std::overflow_error with the Python loop's message on a blow-up (the state stays).
  void step_period() override { step(start_ + k_ * period_); }

  void set_state(const Vec& q, const Vec& v, long period, double work) override {
    integrator_->restart();
    q_ = q;
    v_ = v;
    k_ = period;
    work_ = work;
  }

  // A new run from (q, v) at period 0 with the law, wrenches and settings kept (batch.hpp): the
  // state, work, integrator and the closed plant's warm start are reset as configure() resets
  // them. Only a law without a state of its own can be kept (not the detumbling laws).
  void restart(const Vec& q, const Vec& v) override {
    if (has_law_state()) throw std::invalid_argument("a detumbling law keeps a state: its runs cannot share a loop");
    set_state(q, v, 0, 0.0);
    closed_.forget();
  }
  bool has_law_state() const override { return detumbling_.has_value() || loop_law_.has_value(); }

  // The plant's bodies for the next run (batch.hpp): per joint 1..njoints-1, mass (kg), CoM in the
  // joint frame (3, m) and rotational inertia about the CoM in joint-frame axes (3, 3 row-major,
  // kg m^2), 13 numbers each (pin_plant.hpp's set_bodies: a model equal to the rebuilt one bit for
  // bit); placements, armature and gravity stay.
  void set_bodies(const double* bodies) override {
    freefloat::sim::set_bodies(*model_, bodies);
    if (kernel_) kernel_->set_bodies(bodies);
    closed_.forget();
    refresh_numbers();
  }

  // The computed-torque reference's start and displacement (n,) for the next run; the duration
  // and gains stay (set_computed_torque first).
  void set_reference(const Vec& start, const Vec& delta) override {
    if (!reference_) throw std::invalid_argument("set_reference: no computed-torque law is set");
    reference_->start = start;
    reference_->delta = delta;
  }
  bool has_reference() const override { return reference_.has_value(); }

  const Vec& q() const override { return q_; }
  const Vec& v() const override { return v_; }
  long period() const override { return k_; }
  double time() const override { return start_ + k_ * period_; }
  double work() const override { return work_; }
  long evaluations() const override { return integrator_->evaluations() + lockstep_evaluations_; }
  int nq() const override { return freefloat::sim::nq(*model_); }
  int nv() const override { return freefloat::sim::nv(*model_); }
  int njoints() const override { return freefloat::sim::njoints(*model_); }
  int n_joints() const override { return joints_.n; }

  // The plant's ABA at (q, v, tau) (nv,), outside of any run: the kernel's or Pinocchio's (tree_aba()).
  Vec acceleration(const Vec& q, const Vec& v, const Vec& tau) override {
    Vec a(this->nv());
    plant_acceleration(q, v, tau, a);
    return a;
  }

  // Seconds (this thread's CPU time, which the load of other processes does not inflate).
  double time_acceleration(const Vec& q, const Vec& v, const Vec& tau, long calls) override {
    Vec a(this->nv());
    timespec start, end;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &start);
    for (long i = 0; i < calls; ++i) plant_acceleration(q, v, tau, a);
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &end);
    return (end.tv_sec - start.tv_sec + 1e-9 * (end.tv_nsec - start.tv_nsec)) / calls;
  }

  // The generalized Jacobian quantities at (q, v), outside of any run.
  GeneralizedJacobian generalized_jacobian_at(const Vec& q, const Vec& v) override {
    GeneralizedJacobian g;
    generalized_jacobian(*model_, *data_, q, v, base_frame_, ee_frames_, joints_.n, g);
    return g;
  }

  // Runs until period `last` (exclusive) or until `rows` has no free row for a period that
  // records; writes rows from `row`. Returns the rows written; when the state blows up, stops
  // there (the state stays at the last good period) and puts the Python loop's message in `error`.
  int run(long last, Rows& out, int row, std::string& error) override {
    return run_periods(k_, last, start_, period_, record_every_, out.rows, row, error,
                       [&](double t, bool records, int& r) {
                         begin_period(t, records, out, r);
                         step(t);
                       });
  }

  // Row `row` of `out` at the current state and time, with the torques held; the joint reference
  // from `reference` if given, else from the compiled law (or NaN).
  void record_now(Rows& out, int row, const Vec* reference) override { record(out, row, start_ + k_ * period_, reference); }

 private:
  // The model of `arrays`, which must have this loop's joints and frames (`method` names the caller
  // in the error).
  ModelPtr model_like_this(const ModelArrays& arrays, const char* method) const {
    ModelPtr model = build_model(arrays);
    if (!same_structure(*model_, *model))
      throw std::invalid_argument(std::string(method) + ": the model's joints or frames differ from the loop's");
    return model;
  }

  void check_joint(int joint, const char* what) const {
    if (joint < 0 || joint >= this->njoints())
      throw std::invalid_argument(std::string(what) + " out of range");
  }

  // `spec`, a closure on this loop's joints (std::invalid_argument otherwise).
  const ClosureSpec& check_closure(const ClosureSpec& spec) const {
    check_joint(spec.joint1, "closure joint");
    check_joint(spec.joint2, "closure joint");
    for (int r : spec.rotation_rows)
      if (r < 0 || r > 2) throw std::invalid_argument("closure rotation rows must be 0, 1 or 2");
    return spec;
  }

  // The total mass and gravity of the plant's model, after it changed.
  void refresh_numbers() {
    mass_ = total_mass(*model_);
    gravity_ = gravity(*model_);
  }

  bool world() const { return convention_ == Convention::world; }

  // The tree's accelerations a (nv,) at (q, v, tau) without wrenches, by tree_aba().
  void plant_acceleration(const Vec& q, const Vec& v, const Vec& tau, Vec& a) {
    if (aba_ == TreeAba::kernel) kernel_->aba(q.data(), v.data(), tau.data(), kernel::Wrenches{}, a.data());
    else aba(*model_, *data_, q, v, tau, false, world(), a);
  }

  // The kernel's accelerations a (nv,) at (q, v, tau) under the wrenches held.
  void kernel_aba(const Vec& q, const Vec& v, const Vec& tau, Vec& a) {
    a.resize(this->nv());
    kernel_->aba(q.data(), v.data(), tau.data(), held_wrenches(), a.data());
  }

  // The wrenches held (inertial force at the link CoM, inertial torque), as the kernel takes them.
  kernel::Wrenches held_wrenches() {
    kernel_wrenches_.resize(wrenches_.size());
    for (size_t i = 0; i < wrenches_.size(); ++i) {  // inertial force at the link CoM, inertial torque
      kernel::Wrench& k = kernel_wrenches_[i];
      const Wrench& w = wrenches_[i];
      k.joint = w.joint;
      k.world = true;
      for (int r = 0; r < 3; ++r) {
        k.point[r] = w.com[r];
        k.force[r] = w.force[r];
        k.torque[r] = w.torque[r];
      }
    }
    return kernel::Wrenches{kernel_wrenches_.data(), static_cast<int>(kernel_wrenches_.size())};
  }

  // The law's torques at time t for the current state; throws std::overflow_error with the
  // Python loop's message when the detumbling solve fails.
  void control(double t) {
    if (loop_law_) {
      loop_law_torque(t, q_, v_, tau_);
      tau_full_.tail(joints_.n) = tau_;
      return;
    }
    if (!reference_ && !detumbling_) return;
    const int n = joints_.n;
    joints_.get(q_, pos_);
    joint_space();
    if (reference_) {
      Vec qd(n), qdd(n), qddd(n);
      reference_->at(t, qd, qdd, qddd);
      tau_ = H_ * (qddd + kp_ * (qd - pos_) + kd_ * (qdd - v_.tail(n))) + c_;
    } else {
      DetumblingLaw& law = *detumbling_;
      if (!law.hold) law.hold = pos_;
      if (!law.detumbling(t)) {
        tau_ = law.hold_torque(pos_, v_.tail(n), H_, c_);
      } else {
        generalized_jacobian(law_model(), law_data(), q_, v_, base_frame_, ee_frames_, n, law.at_state);
        const std::string error = law.track(v_.tail(n), H_, c_, tau_);
        if (!error.empty()) {
          char when[64];
          std::snprintf(when, sizeof when, "at t = %.6g s: ", t);
          throw std::overflow_error(when + error);
        }
      }
    }
    tau_full_.tail(n) = tau_;
  }

  void loop_law_torque(double t, const Vec& q, const Vec& v, Vec& tau) {
    generalized_jacobian(*model_, *data_, q, v, base_frame_, ee_frames_, joints_.n, loop_law_->at_state);
    loop_law_->torque(*model_, *data_, closed_, q, v, nb_, t, tau);
  }

  // The laws' model and its Data: set_law_model()'s, else the plant's.
  const Model& law_model() const { return law_model_ ? *law_model_ : *model_; }
  Workspace& law_data() { return law_model_ ? *law_data_ : *data_; }

  // H_ = H* and c_ = c* of tau = H* qddot + c* (the base eliminated through its rows) at the state,
  // on the laws' model.
  void joint_space() {
    mass_matrix(law_model(), law_data(), q_, world(), M_);
    nonlinear_effects(law_model(), law_data(), q_, v_, b_);
    const int n = joints_.n;
    Eigen::MatrixXd rhs(nb_, n + 1);
    rhs.leftCols(n) = M_.topRightCorner(nb_, n);
    rhs.col(n) = b_.head(nb_);
    const Eigen::MatrixXd coupling = M_.topLeftCorner(nb_, nb_).partialPivLu().solve(rhs);
    H_ = M_.bottomRightCorner(n, n) - M_.bottomLeftCorner(n, nb_) * coupling.leftCols(n);
    c_ = b_.tail(n) - M_.bottomLeftCorner(n, nb_) * coupling.col(n);
  }

  // The period at time t up to its step: the law's torques (std::overflow_error when a detumbling
  // solve fails), the wrenches of their profiles, and its telemetry row `row++` when it records.
  void begin_period(double t, bool records, Rows& out, int& row) {
    control(t);
    if (!profiles_.empty()) select_wrenches(profiles_, t, wrenches_);
    if (records) record(out, row++, t, nullptr);
  }

  void step(double t) {
    qn_ = q_;
    vn_ = v_;
    integrator_->advance(dynamics_, qn_, vn_, period_);
    end_step(t);
  }

  // The period at time t after its integration left its end state in (qn_, vn_): the blow-up
  // checks, the work, the state and the period count.
  void end_step(double t) {
    const double t_end = t + period_;
    const double vmax = vn_.cwiseAbs().maxCoeff();
    if (!(vmax < kMaxSpeed))
      fail("state blew up at t = %.6g s (step %ld): max |v| = %.3g (limit %g)", t_end, vmax, kMaxSpeed);
    const double qmax = qn_.cwiseAbs().maxCoeff();
    if (!(qmax < kMaxPosition))
      fail("configuration left the finite range at t = %.6g s (step %ld): max |q| = %.3g (limit %g)", t_end, qmax,
           kMaxPosition);
    if (controlled_) work_ += tau_.dot(difference(*model_, q_, qn_).tail(joints_.n));
    q_.swap(qn_);
    v_.swap(vn_);
    ++k_;
  }

  [[noreturn]] void fail(const char* format, double t, double value, double limit) const {
    char text[256];
    std::snprintf(text, sizeof text, format, t, k_ + 1, value, limit);
    throw std::overflow_error(text);  // OverflowError in Python: a blow-up, not a bad call
  }

  // Row `row` at time t; the joint reference from `reference` if given, else from the compiled law.
  void record(Rows& out, int row, double t, const Vec* reference) {
    const int nq = this->nq(), nv = this->nv(), n = joints_.n, ne = static_cast<int>(ee_frames_.size());
    Snapshot& s = snapshot_;
    snapshot(*model_, *record_data_, q_, v_, base_frame_, ee_frames_, s);
    Eigen::Map<Vec6>(out.momentum + 6 * row) = s.momentum;
    out.t[row] = t;
    Eigen::Map<Vec>(out.q + nq * row, nq) = q_;
    Eigen::Map<Vec>(out.v + nv * row, nv) = v_;
    Eigen::Map<Vec>(out.tau + n * row, n) = tau_;
    joints_.get(q_, pos_);
    Eigen::Map<Vec>(out.joint_positions + n * row, n) = pos_;
    if (reference != nullptr) {
      Eigen::Map<Vec>(out.joint_reference + n * row, n) = *reference;
    } else if (reference_) {
      Vec qd(n), qdd(n), qddd(n);
      reference_->at(t, qd, qdd, qddd);
      Eigen::Map<Vec>(out.joint_reference + n * row, n) = qd;
    } else if (detumbling_ && !detumbling_->detumbling(t)) {  // DetumblingController.reference
      Eigen::Map<Vec>(out.joint_reference + n * row, n) = *detumbling_->hold;
    }
    Eigen::Map<Vec3>(out.com + 3 * row) = s.com;
    out.energy[row] = s.kinetic_energy - mass_ * gravity_.dot(s.com);
    out.work[row] = work_;
    Eigen::Map<Vec3>(out.base_position + 3 * row) = s.base_position;
    Eigen::Map<Eigen::Vector4d>(out.base_quaternion + 4 * row) = Eigen::Quaterniond(s.base_rotation).coeffs();
    Eigen::Map<Vec6>(out.base_twist + 6 * row) = s.base_twist;
    for (int e = 0; e < ne; ++e) {
      Eigen::Map<Vec3>(out.ee_position + 3 * (row * ne + e)) = s.ee_position[e];
      Eigen::Map<Eigen::Vector4d>(out.ee_quaternion + 4 * (row * ne + e)) = Eigen::Quaterniond(s.ee_rotation[e]).coeffs();
    }
  }

  ModelPtr model_;
  WorkspacePtr data_, record_data_;
  std::unique_ptr<kernel::Kernel> kernel_;  // null: the kernel refuses the tree (refusal_)
  std::string refusal_;
  TreeAba aba_ = TreeAba::pinocchio;
  std::vector<kernel::Wrench> kernel_wrenches_;  // wrenches_ as the kernel takes them
  long lockstep_evaluations_ = 0;  // dynamics evaluations of this loop's periods in a LockstepLoops

  friend class LockstepLoops;
  friend std::unique_ptr<Lockstep> make_lockstep(const std::vector<Simulation*>& loops, std::string* why);
  ModelPtr law_model_;     // set_law_model()'s, until configure()
  WorkspacePtr law_data_;  // its Data, kept across runs (the loop's structure never changes)
  JointMap joints_;
  int nb_;
  Convention convention_ = Convention::local;
  std::optional<LieIntegrator> integrator_;  // set by configure()
  std::string integrator_name_;              // its name and substeps
  int substeps_ = 1;
  double period_ = 0.0, start_ = 0.0;
  int record_every_ = 1;
  Dynamics dynamics_;
  std::optional<Quintic> reference_;
  std::optional<DetumblingLaw> detumbling_;
  std::optional<LoopDetumblingLaw> loop_law_;
  ConstrainedDynamics closed_;  // the plant's loop closures (none: ABA)
  bool controlled_ = false;  // torques are held (a law or hold()): the work is accumulated
  std::vector<Wrench> wrenches_;
  std::vector<WrenchProfile> profiles_;
  double kp_ = 0.0, kd_ = 0.0, mass_ = 0.0, work_ = 0.0;
  Vec3 gravity_ = Vec3::Zero();  // m/s^2, inertial frame
  long k_ = 0;
  int base_frame_ = 0;
  std::vector<int> ee_frames_;
  Vec q_, v_, qn_, vn_, tau_full_, tau_, pos_;
  Eigen::MatrixXd M_, H_;
  Vec b_, c_;  // b_: the nonlinear effects (nv,)
  Snapshot snapshot_;  // the telemetry row's quantities
};

}  // namespace freefloat::sim
