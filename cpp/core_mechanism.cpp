// MechanismCore of freefloat.dynamics._core: a closed chain (parallel.hpp) behind pybind11, built
// from ParallelMechanism.core's dicts (py_mechanism.hpp). A translation unit of its own, compiled
// in parallel with core.cpp.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "parallel.hpp"
#include "py_arrays.hpp"
#include "py_mechanism.hpp"

namespace py = pybind11;
using freefloat::py_arrays::Array;
using freefloat::py_arrays::checked;
using freefloat::py_arrays::make_mechanism;
using freefloat::py_arrays::matrix_out;
using freefloat::py_arrays::RowMat;
using freefloat::py_arrays::vector_out;

namespace freefloat {

void bind_mechanism(py::module_& m) {
  py::register_exception<MechanismError>(m, "MechanismError", py::module_::import("freefloat.errors").attr("FreefloatError"));
  py::class_<Mechanism>(m, "MechanismCore")
      .def(py::init(&make_mechanism), py::arg("chains"), py::arg("mechanism"),
           "From one dict of arrays per serial chain and one for the coupling (ParallelMechanism's fields).")
      .def("forward", [](Mechanism& me, const Array& q, const Array& qd, const Array& tau, double baumgarte) {
             const DVec out = me.forward(checked(q, me.n_q, "q"), checked(qd, me.n_q, "qd"),
                                         checked(tau, me.U.cols(), "tau"), baumgarte);
             return vector_out(out);
           }, py::arg("q"), py::arg("qd"), py::arg("tau"), py::arg("baumgarte"), "qddot (n_q,), eq 129.")
      .def("closure", [](Mechanism& me, const Array& q) {
             DVec residual;
             DMat A;
             me.closure(checked(q, me.n_q, "q"), residual, A);
             return py::make_tuple(vector_out(residual), matrix_out(A));
           }, "([qbar; orientation residual] (m,), A (m, n_q)) at q.")
      .def("terms", [](Mechanism& me, const Array& q, const Array& qd) {
             DVec residual, b, v, g;
             DMat A, M;
             me.closure(checked(q, me.n_q, "q"), residual, A);
             me.dynamics(checked(qd, me.n_q, "qd"), b, M, v, g);
             const DMat C = me.velocity_map(A, me.passive_lu(A));
             return py::make_tuple(matrix_out(A), vector_out(b), matrix_out(C), matrix_out(M), vector_out(v), vector_out(g));
           }, "(A, b, C, M', v', g') at (q, qd), as ParallelMechanism.terms.")
      .def("inverse", [](Mechanism& me, const Array& q, const Array& qd_sharp, const Array& qdd_sharp) {
             DVec tau, qd, qdd;
             DMat C;
             me.inverse(checked(q, me.n_q, "q"), checked(qd_sharp, me.p, "qd_sharp"), checked(qdd_sharp, me.p, "qdd_sharp"),
                        tau, qd, qdd, C);
             return py::make_tuple(vector_out(tau), vector_out(qd), vector_out(qdd));
           }, "(tau, qd, qdd) at an assembled q, eqs 130-140.")
      .def("assemble", [](Mechanism& me, const Array& q_sharp, const Array& guess, double tol, int iterations) {
             DVec q(me.n_q);
             q << Eigen::Map<const DVec>(checked(q_sharp, me.p, "q_sharp"), me.p),
                 Eigen::Map<const DVec>(checked(guess, me.n_q - me.p, "guess"), me.n_q - me.p);
             DMat A;
             const bool ok = me.assemble(q, tol, iterations, A);
             return py::make_tuple(vector_out(q), ok);
           }, "(q, converged): Newton on the closure from [q_sharp; guess].")
      .def("trajectory", [](Mechanism& me, const Array& x, const Array& xd, const Array& xdd, const Array& guess,
                            double jump, double tol, int iterations) -> py::tuple {
             const py::ssize_t N = x.size() / me.p, nq = me.n_q, p = me.p;
             const double* xs = checked(x, N * p, "positions");
             const double* xds = checked(xd, N * p, "rates");
             const double* xdds = checked(xdd, N * p, "accelerations");
             py::array_t<double> q_out({N, nq}), tau_out({N, static_cast<py::ssize_t>(me.U.cols())});
             Eigen::Map<RowMat> Q(q_out.mutable_data(), N, nq), T(tau_out.mutable_data(), N, me.U.cols());
             DVec anchor(nq), q(nq), tau, qd, qdd;
             DMat C, A;
             anchor << Eigen::Map<const DVec>(xs, p), Eigen::Map<const DVec>(checked(guess, nq - p, "guess"), nq - p);
             int status = 0;
             py::ssize_t i = 0;
             if (!me.assemble(anchor, tol, iterations, A)) {
               Q.row(0) = anchor.transpose();
               return py::make_tuple(tau_out, q_out, 1, py::ssize_t{0});
             }
             C = me.velocity_map(A, me.passive_lu(A));
             for (; i < N; ++i) {
               const Eigen::Map<const DVec> xi(xs + i * p, p);
               q << xi, anchor.tail(nq - p) + C.bottomRows(nq - p) * (xi - anchor.head(p));
               const DVec predicted = q.tail(nq - p);
               if (!me.assemble(q, tol, iterations, A)) {
                 q.tail(nq - p) = predicted;
                 status = 1;
               } else if ((q.tail(nq - p) - predicted).cwiseAbs().maxCoeff() > jump) {
                 status = 2;
               }
               Q.row(i) = q.transpose();
               if (status) break;
               me.inverse_at(A, xds + i * p, xdds + i * p, tau, qd, qdd, C);
               T.row(i) = tau.transpose();
               anchor = q;
             }
             return py::make_tuple(tau_out, q_out, status, i);
           }, "(tau (N, k), q (N, n_q), status, index): inverse dynamics along a path by continuation; status 1 = no "
              "assembly at index (q holds the prediction), 2 = a jump larger than `jump` at index.");
}

}  // namespace freefloat
