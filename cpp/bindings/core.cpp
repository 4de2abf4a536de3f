// freefloat.dynamics._core: the compiled GJM (gjm/gjm.hpp) behind a small pybind11 interface. The tree
// is handed over as arrays (no C++ object is shared with pin's bindings); outputs are new C-order
// numpy arrays with the shapes of the numpy reference. This unit holds the bindings only: the GJM
// quantities (gjm/gjm.cpp) and the models with their solver (gjm/models.cpp) are translation
// units of their own without pybind11, and the closed chains' MechanismCore is bound in chains.cpp
// (shared with _sim); all compile in parallel.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <initializer_list>
#include <stdexcept>
#include <string>

#include "gjm/gjm.hpp"
#include "gjm/models.hpp"
#include "gjm/tree_solve.hpp"
#include "py_arrays.hpp"

namespace py = pybind11;
using namespace freefloat;
using freefloat::py_arrays::Array;
using freefloat::py_arrays::checked;
using freefloat::py_arrays::IntArray;

namespace freefloat {
void bind_mechanism(py::module_& m);  // chains.cpp
}

namespace {

// A new C-order float64 numpy array of shape `dims`, made through numpy's C API in one call
// (pybind11's array_t(shape) also builds its shape and strides as vectors: on the small arrays of
// gjm.compute, a good part of their cost). With `data`, the array views it and owns `base`.
py::array_t<double> fresh(std::initializer_list<Py_intptr_t> dims, double* data = nullptr,
                          py::handle base = py::handle()) {
  auto& api = py::detail::npy_api::get();
  PyObject* a = api.PyArray_NewFromDescr_(api.PyArray_Type_, api.PyArray_DescrFromType_(py::detail::npy_api::NPY_DOUBLE_),
                                          static_cast<int>(dims.size()), dims.begin(), nullptr, data,
                                          data ? py::detail::npy_api::NPY_ARRAY_WRITEABLE_ : 0, nullptr);
  if (!a) throw py::error_already_set();
  if (data && api.PyArray_SetBaseObject_(a, base.inc_ref().ptr()) != 0) {
    Py_DECREF(a);
    throw py::error_already_set();
  }
  return py::reinterpret_steal<py::array_t<double>>(a);
}

// Row-major copies of an Eigen vector (n,) and matrix (rows, cols) in fresh arrays.
template <typename V>
py::array_t<double> vector_copy(const V& x) {
  py::array_t<double> out = fresh({static_cast<Py_intptr_t>(x.size())});
  Eigen::Map<VecX>(out.mutable_data(), x.size()) = x;
  return out;
}
template <typename M>
py::array_t<double> matrix_copy(const M& m) {
  py::array_t<double> out = fresh({static_cast<Py_intptr_t>(m.rows()), static_cast<Py_intptr_t>(m.cols())});
  Eigen::Map<MatX>(out.mutable_data(), m.rows(), m.cols()) = m;
  return out;
}

py::array_t<double> stack3(const std::vector<Vec3>& xs, size_t first = 0) {
  py::array_t<double> out = fresh({static_cast<Py_intptr_t>(xs.size() - first), 3});
  double* p = out.mutable_data();
  for (size_t i = first; i < xs.size(); ++i, p += 3) Eigen::Map<Vec3>{p} = xs[i];
  return out;
}

py::array_t<double> stack33(const std::vector<Mat3>& xs) {
  py::array_t<double> out = fresh({static_cast<Py_intptr_t>(xs.size()), 3, 3});
  double* p = out.mutable_data();
  for (size_t i = 0; i < xs.size(); ++i, p += 9) Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>{p} = xs[i];
  return out;
}

Tree make_tree(const IntArray& parent, const Array& placement, const Array& axis, py::array_t<bool> revolute,
               const Array& mass, const Array& com, const Array& inertia, const IntArray& q_index,
               py::array_t<bool> circle, bool free_base, const Array& base_com, const Array& base_com_rotation,
               const IntArray& ee_body, const Array& ee_offset) {
  Tree t;
  t.n = static_cast<int>(parent.size());
  const int n = t.n, nb = n + 1;
  const double* pl = checked(placement, 16 * n, "placement");
  const double* ax = checked(axis, 3 * n, "axis");
  const double* ms = checked(mass, nb, "mass");
  const double* cm = checked(com, 3 * nb, "com");
  const double* in = checked(inertia, 9 * nb, "inertia");
  if (revolute.size() != n || q_index.size() != n || circle.size() != n)
    throw std::invalid_argument("revolute, q_index, circle: expected one entry per joint");
  for (int j = 0; j < n; ++j) {
    const int a = static_cast<int>(parent.data()[j]);
    if (a < 0 || a > j) throw std::invalid_argument("parent[" + std::to_string(j) + "]: a parent must come before its child");
    t.parent.push_back(a);
    Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> H(pl + 16 * j);
    t.place_R.push_back(H.topLeftCorner<3, 3>());
    t.place_t.push_back(H.topRightCorner<3, 1>());
    t.axis.emplace_back(ax[3 * j], ax[3 * j + 1], ax[3 * j + 2]);
    t.revolute.push_back(revolute.data()[j]);
    t.q_index.push_back(static_cast<int>(q_index.data()[j]));
    t.circle.push_back(circle.data()[j]);
  }
  for (int b = 0; b < nb; ++b) {
    t.mass.push_back(ms[b]);
    t.com.emplace_back(cm[3 * b], cm[3 * b + 1], cm[3 * b + 2]);
    t.inertia.push_back(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(in + 9 * b));
  }
  t.moves.assign(static_cast<size_t>(nb) * n, 0);
  for (int b = 1; b < nb; ++b) {
    const int a = t.parent[b - 1];
    for (int j = 0; j < n; ++j) t.moves[b * n + j] = t.moves[a * n + j];
    t.moves[b * n + b - 1] = 1;
  }
  t.index_paths();
  t.free_base = free_base;
  const double* bc = checked(base_com, 3, "base_com");
  t.base_com = Vec3(bc[0], bc[1], bc[2]);
  t.base_com_rotation = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
      checked(base_com_rotation, 9, "base_com_rotation"));
  const py::ssize_t k = ee_body.size();
  const double* eo = checked(ee_offset, 3 * k, "ee_offset");
  for (py::ssize_t e = 0; e < k; ++e) {
    const int b = static_cast<int>(ee_body.data()[e]);
    if (b < 0 || b > n) throw std::invalid_argument("ee_body[" + std::to_string(e) + "]: no such body");
    t.ee_body.push_back(b);
    t.ee_offset.emplace_back(eo[3 * e], eo[3 * e + 1], eo[3 * e + 2]);
  }
  return t;
}

// A row-major matrix handed to numpy without a copy: the array owns it (the state's copy is left
// empty and reallocated by the next compute).
py::array_t<double> take(MatX& m) {
  auto* owned = new MatX(std::move(m));
  py::capsule free(owned, [](void* p) { delete static_cast<MatX*>(p); });
  return fresh({static_cast<Py_intptr_t>(owned->rows()), static_cast<Py_intptr_t>(owned->cols())}, owned->data(), free);
}

// (H0, H0m, Hm, Hstar, J0, Jm, J0E, Jstar, momentum_base, momentum_origin, x0dot, qdot,
//  ee_position, (r0, R0, rotation, origin, joint_position, joint_axis, com, inertia)); the dense
// (n, n) and (6k, n) outputs are moved out of `s`.
py::tuple state_out(State& s) {
  const Kinematics& k = s.kin;
  py::tuple kin = py::make_tuple(vector_copy(k.r0), matrix_copy(k.R0), stack33(k.rotation), stack3(k.origin),
                                 stack3(k.origin, 1), stack3(k.joint_axis), stack3(k.com), stack33(k.inertia));
  return py::make_tuple(matrix_copy(s.H0), matrix_copy(s.H0m), take(s.Hm), take(s.Hstar), matrix_copy(s.J0),
                        take(s.Jm), matrix_copy(s.J0E), take(s.Jstar), vector_copy(s.momentum_base),
                        vector_copy(s.momentum_origin), vector_copy(s.x0dot), vector_copy(s.qdot),
                        matrix_copy(s.ee_position), kin);
}

// A new zeroed numpy array of `shape` (calloc: the zeros cost nothing until written).
py::array_t<double> zeros(py::tuple shape) { return py::module_::import("numpy").attr("zeros")(shape); }

// (dH0, dH0m, dHm, H0dot, H0mdot, Hmdot) dense, from the nonzero columns and entries.
py::tuple derivatives_out(const Tree& t, const Derivatives& d, const VecX& qdot) {
  const py::ssize_t n = t.n;
  py::array_t<double> dH0m = zeros(py::make_tuple(n, 6, n)), dHm = zeros(py::make_tuple(n, n, n));
  py::array_t<double> Hmdot = zeros(py::make_tuple(n, n));
  double *columns = dH0m.mutable_data(), *entries = dHm.mutable_data(), *rate = Hmdot.mutable_data();
  for (py::ssize_t k = 0; k < n; ++k) {
    for (const Derivatives::Column& c : d.dH0m_columns[k])
      for (int r = 0; r < 6; ++r) columns[(k * 6 + r) * n + c.j] = c.value[r];
    for (const Derivatives::Entry& e : d.dHm_entries[k]) {
      entries[(k * n + e.i) * n + e.j] = entries[(k * n + e.j) * n + e.i] = e.value;
      rate[e.i * n + e.j] += qdot[k] * e.value;
      if (e.i != e.j) rate[e.j * n + e.i] += qdot[k] * e.value;
    }
  }
  py::array_t<double> dH0 = fresh({n, 6, 6});
  std::copy(d.dH0.begin(), d.dH0.end(), dH0.mutable_data());
  return py::make_tuple(dH0, dH0m, dHm, matrix_copy(d.H0dot), matrix_copy(d.H0mdot),
                        Hmdot);
}

struct Core {
  Tree tree;
  int nq, nv;
  State state;
  Derivatives deriv;
  TreeSolver solver;

  Core(Tree t, int nq_, int nv_) : tree(std::move(t)), nq(nq_), nv(nv_), solver(tree) {}

  void run(const Array& q, const Array& v) {
    compute(tree, checked(q, nq, "q"), checked(v, nv, "v"), state);
  }

  // What the models need (no dense outputs), with the derivatives.
  void run_dynamics(const Array& q, const Array& v) {
    compute_inertia(tree, checked(q, nq, "q"), checked(v, nv, "v"), state);
    derivatives(tree, state, deriv);
  }

  MatX sensitivity_rows(const Array& D) const {  // NIDC's D (n, 6), or zeros when empty
    if (D.size() == 0) return MatX::Zero(tree.n, 6);
    return Eigen::Map<const MatX>(checked(D, 6 * tree.n, "D"), tree.n, 6);
  }

  // Forward dynamics of one model: Pinocchio's a (nv,) (models.hpp's forward_dynamics).
  py::array_t<double> acceleration(const std::string& name, const Array& q, const Array& v, const Array& tau,
                                   const Array& F, const Array& Q_q, const Array& D) {
    const Variant variant = variant_of(name);
    run_dynamics(q, v);
    const Vec6 force = Eigen::Map<const Vec6>(checked(F, 6, "F"));
    const double *joint_tau = checked(tau, nv, "tau") + (nv - tree.n), *joint_Q = checked(Q_q, tree.n, "Q_q");
    py::array_t<double> a = fresh({nv});
    forward_dynamics(tree, state, deriv, solver, variant, force, sensitivity_rows(D), joint_tau, joint_Q, q.data(),
                     v.data(), nv, a.mutable_data());
    return a;
  }

  // (H, c) with tau + Q_q = H qddot + c, F the base rows' generalized force (gravity).
  py::tuple joint_space(const std::string& name, const Array& q, const Array& v, const Array& F, const Array& D) {
    const Variant variant = variant_of(name);
    compute_inertia(tree, checked(q, nq, "q"), checked(v, nv, "v"), state);
    compute_generalized_inertia(tree, state);
    derivatives(tree, state, deriv);
    const Vec6 force = Eigen::Map<const Vec6>(checked(F, 6, "F"));
    const ModelResult r = model_terms(tree, state, deriv, variant, force, sensitivity_rows(D));
    return py::make_tuple(take(state.Hstar), vector_copy(r.c));
  }

  // NIDC's dxdot0/dq_k (n, 6) at (q, v) with the augmented partials of D.
  py::array_t<double> sensitivity(const Array& q, const Array& v, bool translation, const Array& D) {
    run_dynamics(q, v);
    return matrix_copy(nidc_sensitivity(tree, state, deriv, sensitivity_rows(D), translation));
  }
};

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "Compiled GJM quantities and derivatives; the numpy modules of freefloat.dynamics.gjm are the reference.";
  py::list models;
  for (const std::string& name : variant_names()) models.append(name);
  m.attr("MODELS") = models;
  py::class_<Core>(m, "GJMCore")
      .def(py::init([](const IntArray& parent, const Array& placement, const Array& axis, py::array_t<bool> revolute,
                       const Array& mass, const Array& com, const Array& inertia, const IntArray& q_index,
                       py::array_t<bool> circle, bool free_base, const Array& base_com,
                       const Array& base_com_rotation, const IntArray& ee_body, const Array& ee_offset, int nq,
                       int nv) {
             return Core(make_tree(parent, placement, axis, revolute, mass, com, inertia, q_index, circle, free_base,
                                   base_com, base_com_rotation, ee_body, ee_offset),
                         nq, nv);
           }),
           py::arg("parent"), py::arg("placement"), py::arg("axis"), py::arg("revolute"), py::arg("mass"),
           py::arg("com"), py::arg("inertia"), py::arg("q_index"), py::arg("circle"), py::arg("free_base"),
           py::arg("base_com"), py::arg("base_com_rotation"), py::arg("ee_body"), py::arg("ee_offset"),
           py::arg("nq"), py::arg("nv"))
      .def("compute", [](Core& c, const Array& q, const Array& v) {
             c.run(q, v);
             return state_out(c.state);
           }, "GJM quantities at (q, v): a tuple in GJMState field order, kinematics as a tuple.")
      .def("compute_with_derivatives", [](Core& c, const Array& q, const Array& v) {
             c.run(q, v);
             derivatives(c.tree, c.state, c.deriv);
             py::tuple deriv = derivatives_out(c.tree, c.deriv, c.state.qdot);
             return py::make_tuple(state_out(c.state), deriv);
           }, "(state tuple, derivative tuple in GJMDerivatives field order) at (q, v).")
      .def("derivatives", [](Core& c, const Array& q, const Array& v) {
             c.run_dynamics(q, v);
             return derivatives_out(c.tree, c.deriv, c.state.qdot);
           }, "Derivative tuple in GJMDerivatives field order at (q, v).")
      .def("admissible", [](const Core& c, const Array& q, const Array& v, double tolerance, double largest) {
             return freefloat::admissible(c.tree, checked(q, c.nq, "q"), c.nq, checked(v, c.nv, "v"), c.nv, tolerance, largest);
           }, py::arg("q"), py::arg("v"), py::arg("tolerance"), py::arg("largest"),
           "Whether (q, v) passes check_state: finite, at most `largest` in size, unit blocks within `tolerance` of norm 1.")
      .def("acceleration", &Core::acceleration, py::arg("name"), py::arg("q"), py::arg("v"), py::arg("tau"),
           py::arg("F"), py::arg("Q_q"), py::arg("D"),
           "Forward dynamics (nv,) of the named GJM model; F (6,) and Q_q (n,) generalized forces, D NIDC's (n, 6) or empty.")
      .def("joint_space", &Core::joint_space, py::arg("name"), py::arg("q"), py::arg("v"), py::arg("F"), py::arg("D"),
           "(H, c) with tau = H qddot + c of the named GJM model.")
      .def("sensitivity", &Core::sensitivity, py::arg("q"), py::arg("v"), py::arg("translation"), py::arg("D"),
           "NIDC's dxdot0/dq_k (n, 6), eq 64.");

  freefloat::bind_mechanism(m);
}
