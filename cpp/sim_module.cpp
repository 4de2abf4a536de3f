// freefloat.dynamics._sim: the compiled simulation loop (sim/loop.hpp) on Pinocchio's own C++
// algorithms, behind a small pybind11 interface. The model is handed over as arrays and rebuilt;
// telemetry chunks are numpy arrays filled in place.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>

#include "sim/loop.hpp"

namespace py = pybind11;
using namespace freefloat::sim;
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using OutArray = py::array_t<double, py::array::c_style>;

namespace {

const double* sized(const Array& a, py::ssize_t size, const char* name) {
  if (a.size() != size)
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(size) + " numbers, got " +
                                std::to_string(a.size()));
  return a.data();
}

Vec vec(const Array& a, py::ssize_t size, const char* name) { return Eigen::Map<const Vec>(sized(a, size, name), size); }

py::array_t<double> out(const Vec& x) {
  py::array_t<double> r(x.size());
  Eigen::Map<Vec>(r.mutable_data(), x.size()) = x;
  return r;
}

// The telemetry fields in Telemetry's order: (t, q, v, tau, joint_positions, joint_reference,
// base_position, base_quaternion, base_twist, ee_position, ee_quaternion, com, momentum, energy, work).
Rows rows_of(const Model& m, int n_joints, int n_ee, py::tuple arrays) {
  if (arrays.size() != 15) throw std::invalid_argument("telemetry: expected the 15 arrays of Telemetry");
  Rows r;
  r.rows = static_cast<int>(arrays[0].cast<OutArray>().size());
  const long widths[15] = {1, m.nq, m.nv, n_joints, n_joints, n_joints, 3, 4, 6, 3L * n_ee, 4L * n_ee, 3, 6, 1, 1};
  double** fields[15] = {&r.t, &r.q, &r.v, &r.tau, &r.joint_positions, &r.joint_reference, &r.base_position,
                         &r.base_quaternion, &r.base_twist, &r.ee_position, &r.ee_quaternion, &r.com, &r.momentum,
                         &r.energy, &r.work};
  for (int i = 0; i < 15; ++i) {
    py::object item = arrays[i];
    if (!py::isinstance<OutArray>(item) || !item.cast<py::array>().dtype().is(py::dtype::of<double>()) ||
        !(item.cast<py::array>().flags() & py::array::c_style))
      throw std::invalid_argument("telemetry field " + std::to_string(i) + ": expected a C-contiguous float64 array");
    OutArray a = item.cast<OutArray>();
    if (a.size() != r.rows * widths[i])
      throw std::invalid_argument("telemetry field " + std::to_string(i) + ": expected " +
                                  std::to_string(r.rows * widths[i]) + " numbers, got " + std::to_string(a.size()));
    *fields[i] = a.mutable_data();
  }
  return r;
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
  ModelArrays a{parent, kind, name, sized(subspace, 6 * n, "subspace"), sized(placement, 16 * n, "placement"),
                sized(mass, n, "mass"), sized(lever, 3 * n, "lever"), sized(rotational, 9 * n, "rotational"),
                armature.data(), sized(gravity, 3, "gravity"), frame_parent, sized(frame_placement, 16 * f, "frame_placement")};
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

}  // namespace

PYBIND11_MODULE(_sim, m) {
  m.doc() = "The compiled simulation loop on Pinocchio's C++ algorithms (see freefloat.dynamics.compiled).";
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
           [](PySimulation& s, long last, py::tuple arrays, int row) {
             Rows r = s.rows(arrays);
             if (row < 0 || row > r.rows) throw std::invalid_argument("row out of range");
             std::string error;
             int written;
             {
               py::gil_scoped_release release;
               written = s.sim->run(last, r, row, error);
             }
             return py::make_tuple(written, error.empty() ? py::object(py::none()) : py::object(py::str(error)));
           },
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
             const py::ssize_t k = static_cast<py::ssize_t>(joints.size());
             const double *c = sized(com, 3 * k, "com"), *f = sized(force, 3 * k, "force"), *t = sized(torque, 3 * k, "torque");
             std::vector<Simulation::Wrench> w;
             for (py::ssize_t i = 0; i < k; ++i) {
               if (joints[i] < 1 || joints[i] >= static_cast<int>(s.sim->model().njoints))
                 throw std::invalid_argument("wrench joint out of range");
               w.push_back({joints[i], Eigen::Map<const Vec3>(c + 3 * i), Eigen::Map<const Vec3>(f + 3 * i),
                            Eigen::Map<const Vec3>(t + 3 * i)});
             }
             s.sim->set_wrenches(std::move(w));
           },
           "Wrenches held from now on (joint, CoM in its frame, inertial force and torque, scaled).")
      .def_property_readonly("q", [](const PySimulation& s) { return out(s.sim->q()); })
      .def_property_readonly("v", [](const PySimulation& s) { return out(s.sim->v()); })
      .def_property_readonly("periods_done", [](const PySimulation& s) { return s.sim->period(); })
      .def_property_readonly("work", [](const PySimulation& s) { return s.sim->work(); })
      .def_property_readonly("evaluations", [](const PySimulation& s) { return s.sim->evaluations(); });
}
