// The closed chains' bindings of both modules: MechanismCore of freefloat.dynamics._core (a
// closed chain, chains/mechanism.hpp, built from ParallelMechanism.core's dicts by py_mechanism.hpp) and
// ChainSimulation of freefloat.dynamics._sim (the closed-chain loop, sim/chain_loop.hpp, with its
// platform law). One translation unit, compiled once and linked into both modules: compiled once
// per module, the chain code they share cost 36 s more of the build's CPU (g++ 12, -O3). Bindings
// only: the numerics are units of their own without pybind11 (chains/mechanism.cpp,
// chains/inverse.cpp, sim/chain_loop.cpp); the one unit of both took 1.6 GB of compiler memory.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <utility>
#include <vector>

#include "chains/mechanism.hpp"
#include "py_arrays.hpp"
#include "py_mechanism.hpp"
#include "py_sim.hpp"
#include "sim/chain_loop.hpp"

namespace py = pybind11;
using namespace freefloat::sim;
using namespace freefloat::sim::py_sim;
using freefloat::Mechanism;
using freefloat::py_arrays::make_mechanism;
using freefloat::py_arrays::matrix_out;
using freefloat::py_arrays::RowMat;
using freefloat::py_arrays::vector_out;

namespace {

// PlantTelemetry's fields in order: (t, q, v, efforts, reference, drift, orientation_drift).
ChainRows chain_rows_of(int n_q, int k, int r, py::tuple arrays) {
  const auto [rows, d] = fields_of(arrays, {1, n_q, n_q, k, r, 1, 1}, "PlantTelemetry");
  return ChainRows{rows, d[0], d[1], d[2], d[3], d[4], d[5], d[6]};
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
    law.T = Eigen::Map<const RowMat>(checked(T, p * p, "T"), p, p);
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

}  // namespace

void freefloat::sim::bind_chain(py::module_& m) {
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
             const DMat C = me.velocity_map(A);
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
                            double jump, double tol, int iterations) {
             const py::ssize_t N = x.size() / me.p, nq = me.n_q, p = me.p;
             const double* xs = checked(x, N * p, "positions");
             const double* xds = checked(xd, N * p, "rates");
             const double* xdds = checked(xdd, N * p, "accelerations");
             const double* start = checked(guess, nq - p, "guess");
             py::array_t<double> q_out({N, nq}), tau_out({N, static_cast<py::ssize_t>(me.U.cols())});
             const auto [status, index] = me.trajectory(N, xs, xds, xdds, start, jump, tol, iterations,
                                                        q_out.mutable_data(), tau_out.mutable_data());
             return py::make_tuple(tau_out, q_out, status, py::ssize_t{index});
           }, "(tau (N, k), q (N, n_q), status, index): inverse dynamics along a path by continuation; status 1 = no "
              "assembly at index (q holds the prediction), 2 = a jump larger than `jump` at index.");
}

}  // namespace freefloat
