// freefloat.dynamics._sim.Kernel: the dynamics kernel (kernel/kernel.hpp) for Python, one state or
// four in lockstep, with its cost per call timed in C++ (freefloat bench --suite kernel). Bound in
// the module's unit (sim.cpp calls bind_kernel): a unit of its own parsed pybind11 again for 17 s
// of CPU and 0.44 GiB, against 1-2.5 s and 0.09 GiB more there. No Pinocchio header.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <time.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kernel/kernel.hpp"
#include "py_sim.hpp"

namespace freefloat::sim {

namespace py_kernel {

namespace py = pybind11;
using kernel::Kernel;
using py_sim::Array;
using py_sim::checked;
constexpr int kLanes = Kernel::kLanes;

// Pinocchio's fext of joints 1..: (bodies, 6) [force; torque about the joint origin], joint frame.
inline std::vector<kernel::Wrench> local_wrenches(const double* f, int bodies) {
  std::vector<kernel::Wrench> out(bodies);
  for (int b = 0; b < bodies; ++b) {
    out[b].joint = b + 1;
    out[b].world = false;
    for (int r = 0; r < 3; ++r) {
      out[b].force[r] = f[6 * b + r];
      out[b].torque[r] = f[6 * b + 3 + r];
    }
  }
  return out;
}

// This thread's CPU time, s: what a timing on a shared machine reads (other processes' load does
// not inflate it as it inflates the wall clock).
inline double thread_seconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

struct PyKernel {
  std::unique_ptr<Kernel> kernel;
  int bodies;

  // Four states' rows (4, size) of `a`, checked.
  std::vector<const double*> lanes(const Array& a, int size, const char* name) const {
    const double* x = checked(a, static_cast<py::ssize_t>(kLanes) * size, name);
    std::vector<const double*> rows;
    for (int l = 0; l < kLanes; ++l) rows.push_back(x + static_cast<long>(l) * size);
    return rows;
  }

  py::array_t<double> aba(const Array& q, const Array& v, const Array& tau, const std::optional<Array>& fext) {
    const int nq = kernel->nq(), nv = kernel->nv();
    std::vector<kernel::Wrench> w;
    if (fext) w = local_wrenches(checked(*fext, 6L * bodies, "fext"), bodies);
    py::array_t<double> out(nv);
    kernel->aba(checked(q, nq, "q"), checked(v, nv, "v"), checked(tau, nv, "tau"),
                kernel::Wrenches{w.data(), static_cast<int>(w.size())}, out.mutable_data());
    return out;
  }

  py::array_t<double> aba_lanes(const Array& q, const Array& v, const Array& tau, const std::optional<Array>& fext) {
    const int nq = kernel->nq(), nv = kernel->nv();
    const std::vector<const double*> qs = lanes(q, nq, "q"), vs = lanes(v, nv, "v"), ts = lanes(tau, nv, "tau");
    std::vector<std::vector<kernel::Wrench>> w(kLanes);
    kernel::Wrenches lists[kLanes];
    if (fext) {
      const double* f = checked(*fext, 6L * kLanes * bodies, "fext");
      for (int l = 0; l < kLanes; ++l) {
        w[l] = local_wrenches(f + 6L * bodies * l, bodies);
        lists[l] = {w[l].data(), bodies};
      }
    }
    py::array_t<double> out({kLanes, nv});
    double* rows[kLanes];
    for (int l = 0; l < kLanes; ++l) rows[l] = out.mutable_data() + static_cast<long>(l) * nv;
    kernel->aba_lanes(qs.data(), vs.data(), ts.data(), lists, rows);
    return out;
  }

  // Seconds per aba() call (this thread's CPU time), `calls` calls at one state.
  double time_aba(const Array& q, const Array& v, const Array& tau, long calls) {
    const int nq = kernel->nq(), nv = kernel->nv();
    const double *x = checked(q, nq, "q"), *xd = checked(v, nv, "v"), *u = checked(tau, nv, "tau");
    std::vector<double> a(nv);
    py::gil_scoped_release release;
    const double start = thread_seconds();
    for (long i = 0; i < calls; ++i) kernel->aba(x, xd, u, kernel::Wrenches{}, a.data());
    return (thread_seconds() - start) / calls;
  }

  // Seconds per aba_lanes() call (four states), as time_aba.
  double time_aba_lanes(const Array& q, const Array& v, const Array& tau, long calls) {
    const int nq = kernel->nq(), nv = kernel->nv();
    const std::vector<const double*> qs = lanes(q, nq, "q"), vs = lanes(v, nv, "v"), ts = lanes(tau, nv, "tau");
    std::vector<double> a(static_cast<size_t>(kLanes) * nv);
    double* rows[kLanes];
    for (int l = 0; l < kLanes; ++l) rows[l] = a.data() + static_cast<long>(l) * nv;
    py::gil_scoped_release release;
    const double start = thread_seconds();
    for (long i = 0; i < calls; ++i) kernel->aba_lanes(qs.data(), vs.data(), ts.data(), nullptr, rows);
    return (thread_seconds() - start) / calls;
  }
};

inline PyKernel make_kernel(std::vector<int> parent, std::vector<std::string> kind, std::vector<std::string> name,
                     const Array& subspace, const Array& placement, const Array& mass, const Array& lever,
                     const Array& rotational, const Array& armature, const Array& gravity) {
  const ModelArrays arrays = py_sim::arrays_of(parent, kind, name, subspace, placement, mass, lever, rotational,
                                               armature, gravity, {}, Array(py::array_t<double>(0)));
  std::string why;
  std::unique_ptr<Kernel> k = Kernel::build(arrays, &why);
  if (!k) throw std::invalid_argument(why);
  return PyKernel{std::move(k), static_cast<int>(parent.size())};
}

}  // namespace py_kernel

inline void bind_kernel(pybind11::module_& m) {
  using namespace py_kernel;
  py::class_<PyKernel>(m, "Kernel")
      .def(py::init(&make_kernel), py::arg("parent"), py::arg("kind"), py::arg("name"), py::arg("subspace"),
           py::arg("placement"), py::arg("mass"), py::arg("lever"), py::arg("rotational"), py::arg("armature"),
           py::arg("gravity"),
           "The dynamics kernel of the model of these arrays (as Simulation's, without frames); ValueError naming "
           "the joint it does not have.")
      .def("aba", &PyKernel::aba, py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("fext") = py::none(),
           "Accelerations (nv,) at (q, v) under tau and Pinocchio's fext of joints 1.. ((njoints - 1, 6), joint "
           "frames; None: none).")
      .def("aba_lanes", &PyKernel::aba_lanes, py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("fext") = py::none(),
           "Accelerations (4, nv) of four states (4, nq), (4, nv), (4, nv) in lockstep; fext (4, njoints - 1, 6) "
           "or None.")
      .def("time_aba", &PyKernel::time_aba, py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("calls"),
           "Seconds per aba() call in C++ (this thread's CPU time), mean of `calls` calls at one state.")
      .def("time_aba_lanes", &PyKernel::time_aba_lanes, py::arg("q"), py::arg("v"), py::arg("tau"), py::arg("calls"),
           "Seconds per aba_lanes() call (four states) in C++ (this thread's CPU time), mean of `calls` calls.")
      .def("set_bodies",
           [](PyKernel& k, const Array& bodies) { k.kernel->set_bodies(checked(bodies, 13L * k.bodies, "bodies")); },
           "The bodies of joints 1.. (njoints - 1, 13): mass, CoM (3,) in the joint frame, rotational inertia "
           "(3, 3) about it in joint-frame axes.")
      .def_property_readonly("nq", [](const PyKernel& k) { return k.kernel->nq(); })
      .def_property_readonly("nv", [](const PyKernel& k) { return k.kernel->nv(); })
      .def_property_readonly("root", [](const PyKernel& k) {
        static const char* names[] = {"fixed", "free", "planar"};
        return names[k.kernel->root()];
      }, "The root joint: 'free', 'planar' or 'fixed' (no root joint).")
      .def_property_static(
          "isa", [](py::object) { return Kernel::isa(); },
          [](py::object, const std::string& name) { Kernel::set_isa(name); },
          "The instruction set every kernel evaluates with: 'avx2' (AVX2 and FMA, when the CPU has them) or "
          "'baseline'; set 'baseline' to compare the two.");
  m.attr("KERNEL_LANES") = kLanes;
}

}  // namespace freefloat::sim
