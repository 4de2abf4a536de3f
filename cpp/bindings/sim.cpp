// freefloat.dynamics._sim: the compiled simulation loop (sim/loop.hpp) on Pinocchio's own C++
// algorithms, behind a small pybind11 interface. The model is handed over as arrays and rebuilt;
// telemetry chunks are numpy arrays filled in place. This unit sees the loop through
// sim/simulation.hpp only (no Pinocchio header); the closed-chain loop is bound in chains.cpp.
// Bindings only: the loop's numerics are the translation units of cpp/sim/.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "py_kernel.hpp"
#include "py_sim.hpp"
#include "sim/batch.hpp"
#include "sim/rkmk.hpp"  // integrator_names
#include "sim/simulation.hpp"

namespace py = pybind11;

using namespace freefloat::sim;
using namespace freefloat::sim::py_sim;

namespace {

// Wrenches of `k` rows: joint, CoM in its frame, inertial force and torque.
std::vector<Wrench> wrenches_of(const Simulation& sim, const std::vector<int>& joints, const Array& com, const Array& force,
                                const Array& torque) {
  const py::ssize_t k = static_cast<py::ssize_t>(joints.size());
  const double *c = checked(com, 3 * k, "com"), *f = checked(force, 3 * k, "force"), *t = checked(torque, 3 * k, "torque");
  std::vector<Wrench> w;
  for (py::ssize_t i = 0; i < k; ++i) {
    if (joints[i] < 1 || joints[i] >= sim.njoints()) throw std::invalid_argument("wrench joint out of range");
    w.push_back({joints[i], Eigen::Map<const Vec3>(c + 3 * i), Eigen::Map<const Vec3>(f + 3 * i),
                 Eigen::Map<const Vec3>(t + 3 * i)});
  }
  return w;
}

// The telemetry fields in Telemetry's order: (t, q, v, tau, joint_positions, joint_reference,
// base_position, base_quaternion, base_twist, ee_position, ee_quaternion, com, momentum, energy, work).
Rows rows_of(const Simulation& sim, int n_joints, int n_ee, py::tuple arrays) {
  const auto [rows, d] = fields_of(arrays, {1, sim.nq(), sim.nv(), n_joints, n_joints, n_joints, 3, 4, 6, 3L * n_ee, 4L * n_ee,
                                            3, 6, 1, 1}, "Telemetry");
  return Rows{rows, d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7], d[8], d[9], d[10], d[11], d[12], d[13], d[14]};
}

struct PySimulation {
  std::unique_ptr<Simulation> sim;
  int n_joints, n_ee;
  Rows bound{};             // the chunk bind() gave, for record()
  py::object bound_arrays;  // keeps its arrays alive (null until bind())

  Rows rows(py::tuple arrays) const { return rows_of(*sim, n_joints, n_ee, arrays); }
};

// Binds method `name`(parent, kind, name, subspace, placement, mass, lever, rotational, armature,
// gravity, frame_parent, frame_placement) of Simulation: the model arrays (as the constructor's)
// handed to `use`.
template <typename Use>
void def_with_model(py::class_<PySimulation>& cls, const char* method, Use use, const char* doc) {
  cls.def(
      method,
      [use](PySimulation& s, std::vector<int> parent, std::vector<std::string> kind, std::vector<std::string> name,
            const Array& subspace, const Array& placement, const Array& mass, const Array& lever,
            const Array& rotational, const Array& armature, const Array& gravity, std::vector<int> frame_parent,
            const Array& frame_placement) {
        use(*s.sim, arrays_of(parent, kind, name, subspace, placement, mass, lever, rotational, armature, gravity,
                              frame_parent, frame_placement));
      },
      py::arg("parent"), py::arg("kind"), py::arg("name"), py::arg("subspace"), py::arg("placement"), py::arg("mass"),
      py::arg("lever"), py::arg("rotational"), py::arg("armature"), py::arg("gravity"), py::arg("frame_parent"),
      py::arg("frame_placement"), doc);
}

PySimulation make(std::vector<int> parent, std::vector<std::string> kind, std::vector<std::string> name,
                  const Array& subspace, const Array& placement, const Array& mass, const Array& lever,
                  const Array& rotational, const Array& armature, const Array& gravity, std::vector<int> frame_parent,
                  const Array& frame_placement, JointMap joints, int n_base, const std::string& integrator,
                  int substeps, double rtol, double atol, double control_period, double start_time, int record_every,
                  int base_frame, std::vector<int> ee_frames) {
  const int n_joints = joints.n, n_ee = static_cast<int>(ee_frames.size());
  std::unique_ptr<Simulation> sim = make_simulation(
      arrays_of(parent, kind, name, subspace, placement, mass, lever, rotational, armature, gravity, frame_parent,
                frame_placement),
      std::move(joints), n_base, integrator, substeps, rtol, atol, control_period, start_time, record_every, base_frame,
      std::move(ee_frames));
  return PySimulation{std::move(sim), n_joints, n_ee};
}

// A detumbling task's rows (into the 6 n_ee end-effector rows) and mission joints, checked.
void check_task_indices(const PySimulation& s, const std::vector<int>& rows, const std::vector<int>& joints) {
  for (int r : rows)
    if (r < 0 || r >= 6 * s.n_ee) throw std::invalid_argument("detumbling row out of range");
  for (int j : joints)
    if (j < 0 || j >= s.n_joints) throw std::invalid_argument("mission joint out of range");
}

DetumblingTask task_of(const PySimulation& s, std::vector<int> rows, std::vector<int> joints, const std::string& method,
                       const std::string& secondary, double rcond) {
  check_task_indices(s, rows, joints);
  if (rows.empty() || joints.empty()) throw std::invalid_argument("detumbling needs rows and mission joints");
  const auto m = DetumblingTask::method_named(method);
  if (m == DetumblingTask::Method::single && (rows.size() != 1 || joints.size() != 1))
    throw std::invalid_argument("method 'single' takes one row and one mission joint");
  if (secondary != "base_angular_velocity" && secondary != "base_twist")
    throw std::invalid_argument("unknown secondary objective '" + secondary + "'");
  return DetumblingTask{std::move(rows), std::move(joints), m, secondary == "base_twist", rcond};
}

// A closure as Python hands it over: (joint1, placement1 (4, 4), joint2, placement2 (4, 4),
// rotation rows), see compiled._closure.
using ClosureTuple = std::tuple<int, Array, int, Array, std::vector<int>>;

ClosureSpec closure_of(const ClosureTuple& c) {
  const auto& [joint1, placement1, joint2, placement2, rotation_rows] = c;
  return ClosureSpec{joint1, joint2, Eigen::Map<const Pose>(checked(placement1, 16, "placement1")),
                     Eigen::Map<const Pose>(checked(placement2, 16, "placement2")), rotation_rows};
}

// A Batch with what it reads and writes kept alive: the loops, the inputs (converted arrays), the rows.
struct PyBatch {
  py::list loops;
  Array q0, v0;
  std::optional<Array> start, delta, bodies;
  py::tuple arrays;
  std::unique_ptr<Batch> batch;  // last: destroyed (its threads joined) before what they use
};

std::unique_ptr<PyBatch> make_batch(py::list loops, Array q0, Array v0, long last, std::optional<Array> start,
                                    std::optional<Array> delta, std::optional<Array> bodies, py::tuple arrays,
                                    int rows_per_run, int slots, int lanes) {
  if (loops.empty()) throw std::invalid_argument("a batch needs at least one loop");
  std::vector<Simulation*> sims;
  const PySimulation& first = loops[0].cast<PySimulation&>();
  const Simulation& m = *first.sim;
  for (py::handle h : loops) {
    PySimulation& s = h.cast<PySimulation&>();
    if (s.sim->nq() != m.nq() || s.sim->nv() != m.nv() || s.n_joints != first.n_joints || s.n_ee != first.n_ee)
      throw std::invalid_argument("the batch's loops must simulate one robot");
    sims.push_back(s.sim.get());
  }
  if (q0.size() % m.nq() != 0) throw std::invalid_argument("q0: expected (runs, nq) numbers");
  const int runs = static_cast<int>(q0.size() / m.nq());
  checked(v0, static_cast<py::ssize_t>(runs) * m.nv(), "v0");
  if (start.has_value() != delta.has_value()) throw std::invalid_argument("start and delta go together");
  if (start) {
    checked(*start, static_cast<py::ssize_t>(runs) * first.n_joints, "start");
    checked(*delta, static_cast<py::ssize_t>(runs) * first.n_joints, "delta");
  }
  if (bodies) checked(*bodies, static_cast<py::ssize_t>(runs) * (m.njoints() - 1) * 13, "bodies");
  if (last < 1 || rows_per_run < 1) throw std::invalid_argument("last and rows_per_run must be >= 1");
  auto b = std::make_unique<PyBatch>(PyBatch{loops, q0, v0, start, delta, bodies, arrays, nullptr});
  b->batch = std::make_unique<Batch>(std::move(sims), lanes, runs, last, b->q0.data(), b->v0.data(),
                                     start ? b->start->data() : nullptr, delta ? b->delta->data() : nullptr,
                                     bodies ? b->bodies->data() : nullptr, first.rows(arrays), rows_per_run, slots);
  return b;
}

}  // namespace

PYBIND11_MODULE(_sim, m) {
  m.doc() = "The compiled simulation loop on Pinocchio's C++ algorithms (see freefloat.dynamics.compiled).";
  m.attr("INTEGRATORS") = integrator_names();
  m.attr("PINOCCHIO_VERSION") = pinocchio_version();  // the libpinocchio this module is linked to
  py::class_<JointMap>(m, "JointMap")
      .def(py::init([](std::vector<int> sq, std::vector<int> sp, std::vector<int> cq, std::vector<int> cp, int n) {
             return JointMap{sq, sp, cq, cp, n};
           }),
           py::arg("scalar_q"), py::arg("scalar_pos"), py::arg("circle_q"), py::arg("circle_pos"), py::arg("n"));
  py::class_<PySimulation> simulation(m, "Simulation");
  simulation
      .def(py::init(&make), py::arg("parent"), py::arg("kind"), py::arg("name"), py::arg("subspace"),
           py::arg("placement"), py::arg("mass"), py::arg("lever"), py::arg("rotational"), py::arg("armature"),
           py::arg("gravity"), py::arg("frame_parent"), py::arg("frame_placement"), py::arg("joints"),
           py::arg("n_base"), py::arg("integrator"), py::arg("substeps"), py::arg("rtol"), py::arg("atol"),
           py::arg("control_period"), py::arg("start_time"), py::arg("record_every"), py::arg("base_frame"),
           py::arg("ee_frames"))
      .def("configure",
           [](PySimulation& s, const std::string& integrator, int substeps, double rtol, double atol,
              double control_period, double start_time, int record_every) {
             if (record_every < 1) throw std::invalid_argument("record_every must be >= 1");
             s.sim->configure(integrator, substeps, rtol, atol, control_period, start_time, record_every);
             s.bound = Rows{};
             s.bound_arrays = py::object();
           },
           py::arg("integrator"), py::arg("substeps"), py::arg("rtol"), py::arg("atol"), py::arg("control_period"),
           py::arg("start_time"), py::arg("record_every"),
           "A new run on this loop's model and Data: the integrator's settings, the period, the start time and "
           "the recording rate; no law, torques, wrenches, work or bound chunk; period 0; evaluations from 0.")
      .def("acceleration",
           [](PySimulation& s, const Array& q, const Array& v, const Array& tau) {
             const Simulation& m = *s.sim;
             return out(s.sim->acceleration(vec(q, m.nq(), "q"), vec(v, m.nv(), "v"), vec(tau, m.nv(), "tau")));
           })
      .def("set_computed_torque",
           [](PySimulation& s, const Array& start, const Array& delta, double duration, double kp, double kd) {
             s.sim->set_computed_torque(Quintic{vec(start, s.n_joints, "start"), vec(delta, s.n_joints, "delta"), duration},
                                        kp, kd);
           })
      .def("set_state",
           [](PySimulation& s, const Array& q, const Array& v, long period, double work) {
             const Simulation& m = *s.sim;
             s.sim->set_state(vec(q, m.nq(), "q"), vec(v, m.nv(), "v"), period, work);
           })
      .def("run",
           [](PySimulation& s, long last, py::tuple arrays, int row) { return run_chunk(*s.sim, last, s.rows(arrays), row); },
           "Runs to period `last` or until the chunk is full: (rows written from `row`, the blow-up "
           "message or None).")
      .def("bind",
           [](PySimulation& s, py::tuple arrays) {
             s.bound = s.rows(arrays);
             s.bound_arrays = arrays;
           },
           "The chunk record() writes into.")
      .def("hold", [](PySimulation& s, const Array& tau) { s.sim->hold(vec(tau, s.n_joints, "tau")); },
           "Hold the joint torques `tau` (n_joints,) from the current period on.")
      .def("record",
           [](PySimulation& s, int row, std::optional<Array> reference) {
             if (!s.bound_arrays || row < 0 || row >= s.bound.rows)
               throw std::invalid_argument("row out of range of the bound chunk");
             std::optional<Vec> ref;
             if (reference) ref = vec(*reference, s.n_joints, "reference");
             s.sim->record_now(s.bound, row, ref ? &*ref : nullptr);
           },
           py::arg("row"), py::arg("reference") = py::none(),
           "Row `row` of the bound chunk at the current state (reference: the joint reference, or None).")
      .def("step", [](PySimulation& s) { s.sim->step_period(); },
           "One control period; OverflowError with the Python loop's message on a blow-up.")
      .def("set_wrenches",
           [](PySimulation& s, std::vector<int> joints, const Array& com, const Array& force, const Array& torque) {
             s.sim->set_wrenches(wrenches_of(*s.sim, joints, com, force, torque));
           },
           "Wrenches held from now on (joint, CoM in its frame, inertial force and torque, scaled).")
      .def("set_wrench_profiles",
           [](PySimulation& s, std::vector<int> joints, const Array& com, const Array& force, const Array& torque,
              const Array& start, const Array& end, const Array& rise) {
             const std::vector<Wrench> full = wrenches_of(*s.sim, joints, com, force, torque);
             const py::ssize_t k = static_cast<py::ssize_t>(full.size());
             const double *t0 = checked(start, k, "start"), *t1 = checked(end, k, "end"), *r = checked(rise, k, "rise");
             std::vector<WrenchProfile> profiles;
             for (py::ssize_t i = 0; i < k; ++i) profiles.push_back({full[i], t0[i], t1[i], r[i]});
             s.sim->set_wrench_profiles(std::move(profiles));
           },
           "Wrenches with their profiles (as set_wrenches, at profile value 1; start, end, rise in s), "
           "selected by run() at the start of each period.")
      .def("set_detumbling",
           [](PySimulation& s, std::vector<int> rows, std::vector<int> joints, const std::string& method,
              const std::string& secondary, double rcond, double start, double kp, double kd, double period,
              std::optional<Array> hold, std::optional<Array> previous) {
             DetumblingLaw law{task_of(s, rows, joints, method, secondary, rcond), start, kp, kd, period};
             if (hold) law.hold = vec(*hold, s.n_joints, "hold");
             if (previous) law.previous = vec(*previous, s.n_joints, "previous");
             s.sim->set_detumbling(std::move(law));
           },
           py::arg("rows"), py::arg("joints"), py::arg("method"), py::arg("secondary"), py::arg("rcond"),
           py::arg("start"), py::arg("kp"), py::arg("kd"), py::arg("period"), py::arg("hold"), py::arg("previous"),
           "The detumbling law (see DetumblingController), with its state so far (hold, previous: None or (n,)).")
      .def("set_closures",
           [](PySimulation& s, const std::vector<ClosureTuple>& closures, double baumgarte) {
             std::vector<ClosureSpec> specs;
             for (const ClosureTuple& c : closures) specs.push_back(closure_of(c));
             s.sim->set_closures(specs, baumgarte);
           },
           py::arg("closures"), py::arg("baumgarte"),
           "The plant's loop closures, each (joint1, placement1 (4, 4), joint2, placement2 (4, 4), rotation "
           "rows), and Baumgarte rate (1/s): the constrained dynamics of closures.ClosedModel replace ABA.")
      .def("closure_solve",
           [](PySimulation& s, const Array& q, const Array& v, const Array& tau) {
             const Simulation& m = *s.sim;
             const ClosureSolution c = s.sim->closure_solve(vec(q, m.nq(), "q"), vec(v, m.nv(), "v"), vec(tau, m.nv(), "tau"));
             return py::make_tuple(out(c.a), out(c.force), out(c.e), c.rank);
           },
           "(a, lambda, e, rank) of the constrained dynamics at (q, v, tau) (closures.solve); "
           "OverflowError when M is not positive definite.")
      .def("set_loop_detumbling",
           [](PySimulation& s, std::vector<int> rows, std::vector<int> joints, double kd, double period,
              double baumgarte, double squeeze, double torque_limit, const ClosureTuple& closure, int target_joint,
              const Array& target_placement, double mass, const Array& inertia, int first_joint,
              const Array& first_placement, std::optional<Array> previous, const Array& force) {
             LoopDetumblingSettings law;
             law.grasp = closure_of(closure);
             if (law.grasp.size() != 6) throw std::invalid_argument("a two-hand grasp is a weld (6 rows)");
             check_task_indices(s, rows, joints);
             law.rows = std::move(rows);
             law.joints = std::move(joints);
             law.kd = kd;
             law.period = period;
             law.baumgarte = baumgarte;
             law.squeeze = squeeze;
             law.limit = torque_limit;
             law.target_joint = target_joint;
             law.target_placement = Eigen::Map<const Pose>(checked(target_placement, 16, "target_placement"));
             law.mass = mass;
             law.inertia = Eigen::Map<const Vec3>(checked(inertia, 3, "inertia"));
             law.first_joint = first_joint;
             law.first_placement = Eigen::Map<const Pose>(checked(first_placement, 16, "first_placement"));
             LoopDetumblingState state;
             if (previous) state.previous = vec(*previous, s.n_joints, "previous");
             state.force = Eigen::Map<const Vec6>(checked(force, 6, "force"));
             s.sim->set_loop_detumbling(law, std::move(state));
           },
           py::arg("rows"), py::arg("joints"), py::arg("kd"), py::arg("period"), py::arg("baumgarte"),
           py::arg("squeeze"), py::arg("torque_limit"), py::arg("closure"), py::arg("target_joint"),
           py::arg("target_placement"), py::arg("mass"), py::arg("inertia"), py::arg("first_joint"),
           py::arg("first_placement"), py::arg("previous"), py::arg("force"),
           "The two-hand detumbling law (see LoopDetumblingController), with its state so far (previous "
           "rates: None or (n,); the closure force lambda (6,)).")
      .def("loop_detumbling_torque",
           [](PySimulation& s, double t, const Array& q, const Array& v) {
             if (!s.sim->has_loop_detumbling()) throw std::invalid_argument("no two-hand law is set");
             const Simulation& m = *s.sim;
             return out(s.sim->loop_detumbling_torque(t, vec(q, m.nq(), "q"), vec(v, m.nv(), "v")));
           },
           "The two-hand law's torques (n,) at time t and (q, v); its state advances as in a run.")
      .def("take_loop_detumbling_state",
           [](PySimulation& s) {
             if (!s.sim->has_loop_detumbling()) throw std::invalid_argument("no two-hand law is set");
             const LoopDetumblingState state = s.sim->take_loop_detumbling_state();
             return py::make_tuple(maybe(state.previous), out(Vec(state.force)), py::cast(state.times),
                                   py::cast(state.residuals), py::cast(state.saturated));
           },
           "(previous rates, closure force, and the log since the last call: period times, rows' residuals, "
           "saturated flags).")
      .def("take_detumbling_state",
           [](PySimulation& s) {
             DetumblingLaw* law = s.sim->detumbling();
             if (law == nullptr) throw std::invalid_argument("no detumbling law is set");
             py::array_t<double> residuals(static_cast<py::ssize_t>(law->residuals.size()));
             std::copy(law->residuals.begin(), law->residuals.end(), residuals.mutable_data());
             law->residuals.clear();
             return py::make_tuple(maybe(law->hold), maybe(law->previous), residuals);
           },
           "(hold, previous rates, residual max of each detumbling period since the last call).")
      .def("generalized_jacobian",
           [](PySimulation& s, const Array& q, const Array& v) {
             const Simulation& m = *s.sim;
             const GeneralizedJacobian g = s.sim->generalized_jacobian_at(vec(q, m.nq(), "q"), vec(v, m.nv(), "v"));
             return py::make_tuple(out(g.Jstar), out(g.J0), out(g.drift), out(Vec(g.base_twist)));
           },
           "(J*, J0, J0E H0^-1 M, H0^-1 M) at (q, v).")
      .def("detumbling_solve",
           [](PySimulation& s, const Array& q, const Array& v, std::vector<int> rows, std::vector<int> joints,
              const std::string& method, const std::string& secondary, double rcond) {
             const Simulation& m = *s.sim;
             const GeneralizedJacobian g = s.sim->generalized_jacobian_at(vec(q, m.nq(), "q"), vec(v, m.nv(), "v"));
             Vec qdot, residual;
             const std::string error = solve(g, task_of(s, rows, joints, method, secondary, rcond), qdot, residual);
             if (!error.empty()) throw std::invalid_argument(error);
             return py::make_tuple(out(qdot), out(residual));
           },
           "(qdot, residual) of the detumbling solve at (q, v).")
      .def_property(
          "convention",
          [](const PySimulation& s) { return s.sim->convention() == Simulation::Convention::world ? "world" : "local"; },
          [](PySimulation& s, const std::string& name) {
            if (name != "local" && name != "world") throw std::invalid_argument("convention must be 'local' or 'world'");
            s.sim->set_convention(name == "world" ? Simulation::Convention::world : Simulation::Convention::local);
          },
          "Pinocchio's convention of the plant's ABA and the law's CRBA, 'local' or 'world' (same numbers to round-off)")
      .def_property(
          "tree_aba",
          [](const PySimulation& s) { return s.sim->tree_aba() == Simulation::TreeAba::kernel ? "kernel" : "pinocchio"; },
          [](PySimulation& s, const std::string& name) {
            if (name != "kernel" && name != "pinocchio")
              throw std::invalid_argument("tree_aba must be 'kernel' or 'pinocchio'");
            s.sim->set_tree_aba(name == "kernel" ? Simulation::TreeAba::kernel : Simulation::TreeAba::pinocchio);
          },
          "The tree's forward dynamics, 'kernel' (freefloat's dynamics kernel) or 'pinocchio' (its ABA); "
          "'kernel' raises ValueError (kernel_refusal) for a tree the kernel refuses")
      .def_property_readonly(
          "kernel_refusal",
          [](const PySimulation& s) {
            const std::string& why = s.sim->kernel_refusal();
            return why.empty() ? py::object(py::none()) : py::object(py::str(why));
          },
          "Why the dynamics kernel refuses this tree (a joint it does not have), or None")
      .def("time_acceleration",
           [](PySimulation& s, const Array& q, const Array& v, const Array& tau, long calls) {
             const Simulation& m = *s.sim;
             const Vec x = vec(q, m.nq(), "q"), xd = vec(v, m.nv(), "v"), u = vec(tau, m.nv(), "tau");
             py::gil_scoped_release release;
             return s.sim->time_acceleration(x, xd, u, calls);
           },
           py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("calls"),
           "Seconds per acceleration() in C++ (tree_aba's; this thread's CPU time), mean of `calls` calls at one "
           "state.")
      .def_property_readonly("q", [](const PySimulation& s) { return out(s.sim->q()); })
      .def_property_readonly("v", [](const PySimulation& s) { return out(s.sim->v()); })
      .def_property_readonly("periods_done", [](const PySimulation& s) { return s.sim->period(); })
      .def_property_readonly("work", [](const PySimulation& s) { return s.sim->work(); })
      .def_property_readonly("evaluations", [](const PySimulation& s) { return s.sim->evaluations(); });
  def_with_model(simulation, "set_model", [](Simulation& sim, const ModelArrays& model) { sim.set_model(model); },
                 "The plant's numbers from these arrays (as the constructor's), for a model of the same joints and "
                 "frames (ValueError otherwise); the loop's Data are kept.");
  def_with_model(simulation, "set_law_model",
                 [](Simulation& sim, const ModelArrays& model) { sim.set_law_model(model); },
                 "The model the computed-torque and detumbling laws compute on when it is not the plant's (a "
                 "controller that keeps the nominal robot), from these arrays (as the constructor's); until the "
                 "next configure(). ValueError for a model of other joints or frames.");

  py::class_<PyBatch>(m, "Batch")
      .def(py::init(&make_batch), py::arg("loops"), py::arg("q0"), py::arg("v0"), py::arg("last"), py::arg("start"),
           py::arg("delta"), py::arg("bodies"), py::arg("arrays"), py::arg("rows_per_run"), py::arg("slots"),
           py::arg("lanes") = 1,
           "Starts the runs from q0 (runs, nq), v0 (runs, nv) to period `last` on one C++ thread per loop "
           "(each configured alike, with no detumbling law), with the quintics' start and delta (runs, n) "
           "under computed torque (else None) and each run's plant bodies (runs, njoints - 1, 13: mass, "
           "CoM (3,) in the joint frame, rotational inertia (3, 3) about it in joint-frame axes; None: the "
           "loops'), writing each run's rows into a free slot "
           "of `rows_per_run` rows of the telemetry arrays (`slots` of them). With `lanes` above 1 the loops run in "
           "lockstep groups of `lanes`, one thread per group (ValueError saying why when they cannot).")
      .def("wait",
           [](PyBatch& b, double seconds) {
             py::gil_scoped_release release;
             return b.batch->wait(seconds);
           },
           "Waits up to `seconds` (Python's lock released) for a run to finish; True when every thread has ended.")
      .def("take",
           [](PyBatch& b) {
             py::list out;
             for (const Batch::Done& d : b.batch->take())
               out.append(py::make_tuple(d.run, d.slot, d.rows, d.periods, d.evaluations, d.wall, d.blow_up, d.failure));
             return out;
           },
           "The runs finished since the last call: (run, slot, rows, periods, evaluations, wall s, the loop's "
           "blow-up message or None, the text of an error the loop threw or None).")
      .def("release", [](PyBatch& b, int slot) { b.batch->release(slot); }, "The slot's rows are read.")
      .def("stop", [](PyBatch& b) { b.batch->stop(); }, "Every run stops at its next slice of periods.");
  bind_chain(m);
  bind_kernel(m);
}
