// A closed chain (chains/mechanism.hpp's Mechanism) from the Python dicts of
// freefloat.parallel.mechanism.ParallelMechanism.core: one dict of arrays per serial chain and one
// for the coupling. Shared by both compiled modules (the core's MechanismCore, the loop's
// ChainSimulation).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "chains/mechanism.hpp"
#include "py_arrays.hpp"

namespace freefloat::py_arrays {

inline DMat dmat(const Array& a, pybind11::ssize_t rows, pybind11::ssize_t cols, const std::string& name) {
  return Eigen::Map<const RowMat>(checked(a, rows * cols, name.c_str()), rows, cols);
}

inline Chain make_chain(const pybind11::dict& c) {
  Chain out;
  const Array placement = c["placement"].cast<Array>();
  out.nu = static_cast<int>(placement.shape(0));
  const int nu = out.nu;
  const Array link = c["link"].cast<Array>(), com = c["com"].cast<Array>(), inertia = c["inertia"].cast<Array>();
  const Array mass = c["mass"].cast<Array>();
  const pybind11::array_t<bool> prismatic = c["prismatic"].cast<pybind11::array_t<bool>>();
  const double* pl = checked(placement, 16 * nu, "placement");
  const double* li = checked(link, 16 * nu, "link");
  const double* cm = checked(com, 3 * nu, "com");
  const double* in = checked(inertia, 9 * nu, "inertia");
  const double* ms = checked(mass, nu, "mass");
  using Row4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
  using Row3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  for (int i = 0; i < nu; ++i) {
    out.placement.push_back(Eigen::Map<const Row4>(pl + 16 * i));
    out.link.push_back(Eigen::Map<const Row4>(li + 16 * i));
    out.prismatic.push_back(prismatic.data()[i]);
    out.mass.push_back(ms[i]);
    out.com.emplace_back(cm[3 * i], cm[3 * i + 1], cm[3 * i + 2]);
    out.inertia.push_back(Eigen::Map<const Row3>(in + 9 * i));
  }
  for (int i = 0; i + 1 < nu; ++i) out.link_next.push_back(out.link[i] * out.placement[i + 1]);
  out.base = Eigen::Map<const Row4>(checked(c["base"].cast<Array>(), 16, "base"));
  const double* tp = checked(c["tip_point"].cast<Array>(), 3, "tip_point");
  const double* gv = checked(c["gravity"].cast<Array>(), 3, "gravity");
  out.tip_point = V3(tp[0], tp[1], tp[2]);
  out.gravity = V3(gv[0], gv[1], gv[2]);
  return out;
}

inline Mechanism make_mechanism(const pybind11::list& chains, const pybind11::dict& m) {
  Mechanism out;
  for (const auto& c : chains) out.chains.push_back(make_chain(c.cast<pybind11::dict>()));
  const Array D = m["D"].cast<Array>(), E = m["E"].cast<Array>(), F = m["F"].cast<Array>();
  out.m_lin = static_cast<int>(D.shape(0));
  out.p = static_cast<int>(D.shape(1));
  int n_passive = 0;
  for (const Chain& c : out.chains) n_passive += c.nu;
  out.n_q = out.p + n_passive;
  const int nc = static_cast<int>(out.chains.size());
  out.D = dmat(D, out.m_lin, out.p, "D");
  out.d = dmat(m["d"].cast<Array>(), out.m_lin, 1, "d");
  out.E = dmat(E, out.m_lin, 3 * nc, "E");
  out.F = dmat(F, out.m_lin, n_passive, "F");
  out.platform_mass = dmat(m["platform_mass"].cast<Array>(), out.p, out.p, "platform_mass");
  out.platform_gravity = dmat(m["platform_gravity"].cast<Array>(), out.p, 1, "platform_gravity");
  const IntArray actuated = m["actuated"].cast<IntArray>();
  out.U = DMat::Zero(out.n_q, actuated.size());
  for (pybind11::ssize_t i = 0; i < actuated.size(); ++i) out.U(actuated.data()[i], i) = 1.0;
  if (!m["offset"].is_none()) {
    out.angular = true;
    const Array offset = m["offset"].cast<Array>();
    out.m_ang = static_cast<int>(offset.size());
    out.offset = dmat(offset, out.m_ang, 1, "offset");
    out.P = dmat(m["P"].cast<Array>(), out.m_ang, out.p, "P");
    out.Q = dmat(m["Q"].cast<Array>(), out.m_ang, 3 * nc, "Q");
    out.R = dmat(m["R"].cast<Array>(), out.m_ang, n_passive, "R");
    const double* ref = checked(m["reference"].cast<Array>(), 9 * nc, "reference");
    for (int c = 0; c < nc; ++c)
      out.reference.push_back(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(ref + 9 * c));
  }
  if (out.m() != n_passive)
    throw std::invalid_argument("the compiled core needs a square passive constraint Jacobian A° (" + std::to_string(out.m()) +
                                " constraints, " + std::to_string(n_passive) + " passive joints)");
  return out;
}

}  // namespace freefloat::py_arrays
