// freefloat.dynamics._sim: the compiled simulation loop (sim/loop.hpp) on Pinocchio's own C++
// algorithms, behind a small pybind11 interface. The model is handed over as arrays and rebuilt;
// telemetry chunks are numpy arrays filled in place.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <utility>
#include <vector>

#include "py_arrays.hpp"
#include "py_mechanism.hpp"
#include "sim/chain_loop.hpp"
#include "sim/loop.hpp"

namespace py = pybind11;
using namespace freefloat::sim;
using freefloat::Mechanism;
using freefloat::py_arrays::Array;
using freefloat::py_arrays::checked;
using OutArray = py::array_t<double, py::array::c_style>;

namespace {

Vec vec(const Array& a, py::ssize_t size, const char* name) { return Eigen::Map<const Vec>(checked(a, size, name), size); }

py::array_t<double> out(const Vec& x) {
  py::array_t<double> r(x.size());
  Eigen::Map<Vec>(r.mutable_data(), x.size()) = x;
  return r;
}

py::array_t<double> out(const Eigen::MatrixXd& x) {
  py::array_t<double> r({x.rows(), x.cols()});
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(r.mutable_data(), x.rows(),
                                                                                    x.cols()) = x;
  return r;
}

py::object maybe(const std::optional<Vec>& x) { return x ? py::object(out(*x)) : py::object(py::none()); }

// Wrenches of `k` rows: joint, CoM in its frame, inertial force and torque.
std::vector<Wrench> wrenches_of(const Model& m, const std::vector<int>& joints, const Array& com, const Array& force,
                                const Array& torque) {
  const py::ssize_t k = static_cast<py::ssize_t>(joints.size());
  const double *c = checked(com, 3 * k, "com"), *f = checked(force, 3 * k, "force"), *t = checked(torque, 3 * k, "torque");
  std::vector<Wrench> w;
  for (py::ssize_t i = 0; i < k; ++i) {
    if (joints[i] < 1 || joints[i] >= static_cast<int>(m.njoints)) throw std::invalid_argument("wrench joint out of range");
    w.push_back({joints[i], Eigen::Map<const Vec3>(c + 3 * i), Eigen::Map<const Vec3>(f + 3 * i),
                 Eigen::Map<const Vec3>(t + 3 * i)});
  }
  return w;
}

// The C-contiguous float64 arrays of one telemetry chunk, field i holding rows * widths[i]
// numbers: (rows, their data). `what` names the telemetry class in errors.
std::pair<int, std::vector<double*>> fields_of(py::tuple arrays, const std::vector<long>& widths, const char* what) {
  if (arrays.size() != widths.size())
    throw std::invalid_argument(std::string("telemetry: expected the ") + std::to_string(widths.size()) +
                                " arrays of " + what);
  const int rows = static_cast<int>(arrays[0].cast<OutArray>().size());
  std::vector<double*> data;
  for (size_t i = 0; i < widths.size(); ++i) {
    py::object item = arrays[i];
    if (!py::isinstance<OutArray>(item) || !item.cast<py::array>().dtype().is(py::dtype::of<double>()) ||
        !(item.cast<py::array>().flags() & py::array::c_style))
      throw std::invalid_argument("telemetry field " + std::to_string(i) + ": expected a C-contiguous float64 array");
    OutArray a = item.cast<OutArray>();
    if (a.size() != rows * widths[i])
      throw std::invalid_argument("telemetry field " + std::to_string(i) + ": expected " +
                                  std::to_string(rows * widths[i]) + " numbers, got " + std::to_string(a.size()));
    data.push_back(a.mutable_data());
  }
  return {rows, data};
}

// The telemetry fields in Telemetry's order: (t, q, v, tau, joint_positions, joint_reference,
// base_position, base_quaternion, base_twist, ee_position, ee_quaternion, com, momentum, energy, work).
Rows rows_of(const Model& m, int n_joints, int n_ee, py::tuple arrays) {
  const auto [rows, d] = fields_of(arrays, {1, m.nq, m.nv, n_joints, n_joints, n_joints, 3, 4, 6, 3L * n_ee, 4L * n_ee,
                                            3, 6, 1, 1}, "Telemetry");
  return Rows{rows, d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7], d[8], d[9], d[10], d[11], d[12], d[13], d[14]};
}

// PlantTelemetry's fields in order: (t, q, v, efforts, reference, drift, orientation_drift).
ChainRows chain_rows_of(int n_q, int k, int r, py::tuple arrays) {
  const auto [rows, d] = fields_of(arrays, {1, n_q, n_q, k, r, 1, 1}, "PlantTelemetry");
  return ChainRows{rows, d[0], d[1], d[2], d[3], d[4], d[5], d[6]};
}

// run() of either compiled loop on a chunk, the GIL released: (rows written from `row`, the
// blow-up message or None).
template <typename Loop, typename Chunk>
py::tuple run_chunk(Loop& loop, long last, Chunk rows, int row) {
  if (row < 0 || row > rows.rows) throw std::invalid_argument("row out of range");
  std::string error;
  int written;
  {
    py::gil_scoped_release release;
    written = loop.run(last, rows, row, error);
  }
  return py::make_tuple(written, error.empty() ? py::object(py::none()) : py::object(py::str(error)));
}

struct PyChain {
  std::unique_ptr<ChainSimulation> sim;
  int n_q, k, r = 0;
  ChainRows bound{};
  py::object bound_arrays;

  ChainRows rows(py::tuple arrays) const { return chain_rows_of(n_q, k, r, arrays); }
};

// set_platform_law's arguments as a PlatformLaw on the nominal model.
PlatformLaw platform_law(const py::list& chains, const py::dict& coupling, const Array& center, double radius,
                         double rate, std::pair<int, int> axes, double lam, bool sliding, bool sign, const Array& n,
                         const Array& T, std::vector<std::pair<int, int>> pairs, std::vector<Array> n_ij, int every) {
  PlatformLaw law;
  if (every < 1) throw std::invalid_argument("every must be >= 1");
  law.every = every;
  law.model = freefloat::py_arrays::make_mechanism(chains, coupling);
  const int p = law.model.p;
  if (axes.first < 0 || axes.first >= p || axes.second < 0 || axes.second >= p)
    throw std::invalid_argument("reference axes out of range of the platform coordinates");
  law.reference = Circle{vec(center, p, "center"), radius, rate, axes.first, axes.second};
  law.lam = lam;
  law.sliding = sliding;
  law.sign = sign;
  if (sliding) {
    law.n = vec(n, p, "n");
    law.T = Eigen::Map<const freefloat::py_arrays::RowMat>(checked(T, p * p, "T"), p, p);
    if (pairs.size() != n_ij.size()) throw std::invalid_argument("n_ij: one array per pair");
    for (size_t i = 0; i < pairs.size(); ++i) {
      if (pairs[i].first < 0 || pairs[i].first >= p || pairs[i].second < 0 || pairs[i].second >= p)
        throw std::invalid_argument("n_ij pair out of range of the platform coordinates");
      law.n_ij.push_back(vec(n_ij[i], p, "n_ij"));
    }
    law.pairs = std::move(pairs);
  }
  return law;
}

struct PySimulation {
  std::unique_ptr<Simulation> sim;
  int n_joints, n_ee;
  Rows bound{};             // the chunk bind() gave, for record()
  py::object bound_arrays;  // keeps its arrays alive (null until bind())

  Rows rows(py::tuple arrays) const { return rows_of(sim->model(), n_joints, n_ee, arrays); }
};

PySimulation make(std::vector<int> parent, std::vector<std::string> kind, std::vector<std::string> name,
                  const Array& subspace, const Array& placement, const Array& mass, const Array& lever,
                  const Array& rotational, const Array& armature, const Array& gravity, std::vector<int> frame_parent,
                  const Array& frame_placement, JointMap joints, int n_base, const std::string& integrator,
                  int substeps, double rtol, double atol, double control_period, double start_time, int record_every,
                  int base_frame, std::vector<int> ee_frames) {
  const py::ssize_t n = static_cast<py::ssize_t>(parent.size()), f = static_cast<py::ssize_t>(frame_parent.size());
  if (kind.size() != parent.size() || name.size() != parent.size())
    throw std::invalid_argument("parent, kind, name: expected one entry per joint");
  ModelArrays a{parent, kind, name, checked(subspace, 6 * n, "subspace"), checked(placement, 16 * n, "placement"),
                checked(mass, n, "mass"), checked(lever, 3 * n, "lever"), checked(rotational, 9 * n, "rotational"),
                armature.data(), checked(gravity, 3, "gravity"), frame_parent, checked(frame_placement, 16 * f, "frame_placement")};
  Model model = build_model(a);
  if (armature.size() != model.nv) throw std::invalid_argument("armature: expected one entry per velocity");
  if (record_every < 1) throw std::invalid_argument("record_every must be >= 1");
  const int frames = static_cast<int>(frame_parent.size());
  for (int id : ee_frames)
    if (id < 0 || id >= frames) throw std::invalid_argument("ee frame index out of range");
  if (base_frame < 0 || base_frame >= frames) throw std::invalid_argument("base frame index out of range");
  auto sim = std::make_unique<Simulation>(std::move(model), joints, n_base, integrator, substeps, rtol, atol,
                                          control_period, start_time, record_every);
  for (int& id : ee_frames) id += 1;  // frame 0 is the universe
  sim->set_frames(base_frame + 1, ee_frames);
  return PySimulation{std::move(sim), joints.n, static_cast<int>(ee_frames.size())};
}

DetumblingTask task_of(const PySimulation& s, std::vector<int> rows, std::vector<int> joints, const std::string& method,
                       const std::string& secondary, double rcond) {
  for (int r : rows)
    if (r < 0 || r >= 6 * s.n_ee) throw std::invalid_argument("detumbling row out of range");
  for (int j : joints)
    if (j < 0 || j >= s.n_joints) throw std::invalid_argument("mission joint out of range");
  if (rows.empty() || joints.empty()) throw std::invalid_argument("detumbling needs rows and mission joints");
  const auto m = DetumblingTask::method_named(method);
  if (m == DetumblingTask::Method::single && (rows.size() != 1 || joints.size() != 1))
    throw std::invalid_argument("method 'single' takes one row and one mission joint");
  if (secondary != "base_angular_velocity" && secondary != "base_twist")
    throw std::invalid_argument("unknown secondary objective '" + secondary + "'");
  return DetumblingTask{std::move(rows), std::move(joints), m, secondary == "base_twist", rcond};
}

}  // namespace

PYBIND11_MODULE(_sim, m) {
  m.doc() = "The compiled simulation loop on Pinocchio's C++ algorithms (see freefloat.dynamics.compiled).";
  m.attr("INTEGRATORS") = integrator_names();
  py::class_<JointMap>(m, "JointMap")
      .def(py::init([](std::vector<int> sq, std::vector<int> sp, std::vector<int> cq, std::vector<int> cp, int n) {
             return JointMap{sq, sp, cq, cp, n};
           }),
           py::arg("scalar_q"), py::arg("scalar_pos"), py::arg("circle_q"), py::arg("circle_pos"), py::arg("n"));
  py::class_<PySimulation>(m, "Simulation")
      .def(py::init(&make), py::arg("parent"), py::arg("kind"), py::arg("name"), py::arg("subspace"),
           py::arg("placement"), py::arg("mass"), py::arg("lever"), py::arg("rotational"), py::arg("armature"),
           py::arg("gravity"), py::arg("frame_parent"), py::arg("frame_placement"), py::arg("joints"),
           py::arg("n_base"), py::arg("integrator"), py::arg("substeps"), py::arg("rtol"), py::arg("atol"),
           py::arg("control_period"), py::arg("start_time"), py::arg("record_every"), py::arg("base_frame"),
           py::arg("ee_frames"))
      .def("acceleration",
           [](PySimulation& s, const Array& q, const Array& v, const Array& tau) {
             const Model& m = s.sim->model();
             return out(s.sim->acceleration(vec(q, m.nq, "q"), vec(v, m.nv, "v"), vec(tau, m.nv, "tau")));
           })
      .def("set_computed_torque",
           [](PySimulation& s, const Array& start, const Array& delta, double duration, double kp, double kd) {
             s.sim->set_computed_torque(Quintic{vec(start, s.n_joints, "start"), vec(delta, s.n_joints, "delta"), duration},
                                        kp, kd);
           })
      .def("set_state",
           [](PySimulation& s, const Array& q, const Array& v, long period, double work) {
             const Model& m = s.sim->model();
             s.sim->set_state(vec(q, m.nq, "q"), vec(v, m.nv, "v"), period, work);
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
             s.sim->set_wrenches(wrenches_of(s.sim->model(), joints, com, force, torque));
           },
           "Wrenches held from now on (joint, CoM in its frame, inertial force and torque, scaled).")
      .def("set_wrench_profiles",
           [](PySimulation& s, std::vector<int> joints, const Array& com, const Array& force, const Array& torque,
              const Array& start, const Array& end, const Array& rise) {
             const std::vector<Wrench> full = wrenches_of(s.sim->model(), joints, com, force, torque);
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
             const Model& m = s.sim->model();
             const GeneralizedJacobian g = s.sim->generalized_jacobian_at(vec(q, m.nq, "q"), vec(v, m.nv, "v"));
             return py::make_tuple(out(g.Jstar), out(g.J0), out(g.drift), out(Vec(g.base_twist)));
           },
           "(J*, J0, J0E H0^-1 M, H0^-1 M) at (q, v).")
      .def("detumbling_solve",
           [](PySimulation& s, const Array& q, const Array& v, std::vector<int> rows, std::vector<int> joints,
              const std::string& method, const std::string& secondary, double rcond) {
             const Model& m = s.sim->model();
             const GeneralizedJacobian g = s.sim->generalized_jacobian_at(vec(q, m.nq, "q"), vec(v, m.nv, "v"));
             Vec qdot, residual;
             const std::string error = solve(g, task_of(s, rows, joints, method, secondary, rcond), qdot, residual);
             if (!error.empty()) throw std::invalid_argument(error);
             return py::make_tuple(out(qdot), out(residual));
           },
           "(qdot, residual) of the detumbling solve at (q, v).")
      .def_property_readonly("q", [](const PySimulation& s) { return out(s.sim->q()); })
      .def_property_readonly("v", [](const PySimulation& s) { return out(s.sim->v()); })
      .def_property_readonly("periods_done", [](const PySimulation& s) { return s.sim->period(); })
      .def_property_readonly("work", [](const PySimulation& s) { return s.sim->work(); })
      .def_property_readonly("evaluations", [](const PySimulation& s) { return s.sim->evaluations(); });
  py::class_<PyChain>(m, "ChainSimulation")
      .def(py::init([](const py::list& chains, const py::dict& coupling, double baumgarte, double max_drift,
                       const std::string& integrator, int substeps, double rtol, double atol, double control_period,
                       double start_time, int record_every, bool per_stage) {
             if (record_every < 1) throw std::invalid_argument("record_every must be >= 1");
             Mechanism plant = freefloat::py_arrays::make_mechanism(chains, coupling);
             const int n_q = plant.n_q, k = static_cast<int>(plant.U.cols());
             return PyChain{std::make_unique<ChainSimulation>(std::move(plant), baumgarte, max_drift, integrator, substeps,
                                                              rtol, atol, control_period, start_time, record_every,
                                                              per_stage),
                            n_q, k};
           }),
           py::arg("chains"), py::arg("coupling"), py::arg("baumgarte"), py::arg("max_drift"), py::arg("integrator"),
           py::arg("substeps"), py::arg("rtol"), py::arg("atol"), py::arg("control_period"), py::arg("start_time"),
           py::arg("record_every"), py::arg("per_stage"),
           "A coupled closed chain (ParallelMechanism.core's dicts) in the compiled loop.")
      .def("set_platform_law",
           [](PyChain& s, const py::list& chains, const py::dict& coupling, const Array& center, double radius,
              double rate, std::pair<int, int> axes, double lam, bool sliding, bool sign, const Array& n, const Array& T,
              std::vector<std::pair<int, int>> pairs, std::vector<Array> n_ij, int every) {
             PlatformLaw law = platform_law(chains, coupling, center, radius, rate, axes, lam, sliding, sign, n, T,
                                            std::move(pairs), std::move(n_ij), every);
             s.r = law.model.p;
             s.sim->set_law(std::move(law));
           },
           py::arg("chains"), py::arg("coupling"), py::arg("center"), py::arg("radius"), py::arg("rate"), py::arg("axes"),
           py::arg("lam"), py::arg("sliding"), py::arg("sign"), py::arg("n"), py::arg("T"), py::arg("pairs"),
           py::arg("n_ij"), py::arg("every") = 1,
           "PlatformControl (computed torque, or sliding mode with eq 167's gains) on a nominal model, evaluated "
           "every `every` control periods.")
      .def("set_state",
           [](PyChain& s, const Array& q, const Array& v, long period) {
             s.sim->set_state(vec(q, s.n_q, "q"), vec(v, s.n_q, "v"), period);
           })
      .def("run",
           [](PyChain& s, long last, py::tuple arrays, int row) { return run_chunk(*s.sim, last, s.rows(arrays), row); },
           "Runs to period `last` or until the chunk is full: (rows written from `row`, the blow-up message or None).")
      .def("bind",
           [](PyChain& s, py::tuple arrays) {
             s.bound = s.rows(arrays);
             s.bound_arrays = arrays;
           })
      .def("hold", [](PyChain& s, const Array& u) { s.sim->hold(vec(u, s.k, "u")); })
      .def("record",
           [](PyChain& s, int row, std::optional<Array> reference) {
             if (!s.bound_arrays || row < 0 || row >= s.bound.rows)
               throw std::invalid_argument("row out of range of the bound chunk");
             std::optional<Vec> ref;
             if (reference) ref = vec(*reference, s.r, "reference");
             s.sim->record(s.bound, row, ref ? &*ref : nullptr);
           },
           py::arg("row"), py::arg("reference") = py::none())
      .def("step", [](PyChain& s) { s.sim->step_period(); },
           "One control period; OverflowError with the Python loop's message on a blow-up.")
      .def("law_efforts",
           [](PyChain& s, double t, const Array& q, const Array& v) {
             if (!s.sim->has_law()) throw std::invalid_argument("no compiled law set");
             return out(s.sim->law_efforts(t, vec(q, s.n_q, "q"), vec(v, s.n_q, "v")));
           })
      .def_property_readonly("q", [](const PyChain& s) { return out(s.sim->q()); })
      .def_property_readonly("v", [](const PyChain& s) { return out(s.sim->v()); })
      .def_property_readonly("periods_done", [](const PyChain& s) { return s.sim->period(); })
      .def_property_readonly("evaluations", [](const PyChain& s) { return s.sim->evaluations(); });
}
