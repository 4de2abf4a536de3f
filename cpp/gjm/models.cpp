// The definitions of models.hpp and tree_solve.hpp: the GJM dynamics models, each function naming
// the method of the numpy reference it mirrors, on the quantities of gjm.cpp, and the tree-sparse
// solver of their forward dynamics. A translation unit without pybind11 (bindings/core.cpp binds
// them).
#include "models.hpp"

#include <stdexcept>
#include <string>
#include <vector>

namespace freefloat {

const std::vector<std::string>& variant_names() {
  static const std::vector<std::string> names{"standard", "standard_full_hdot", "standard_corrected", "nidc",
                                              "nidc_translation", "reduced", "momentum_mono", "momentum_multi",
                                              "momentum_routh"};
  return names;
}

Variant variant_of(const std::string& name) {
  const auto& names = variant_names();
  for (size_t i = 0; i < names.size(); ++i)
    if (name == names[i]) return static_cast<Variant>(i);
  throw std::invalid_argument("unknown compiled dynamics model '" + name + "'");
}

// The helpers of this unit stay `inline`, as in gjm.cpp.
namespace {

using RowMat6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;

// The joint partials dH0/dq_k and dH0m/dq_k a model uses: GJM's, read in place, or NIDC's
// augmented ones. Both are only ever needed times a vector or summed with weights, so NIDC's
// augmentation (linear in D) is applied to those contractions, never stored per joint.
struct Partials {
  const Derivatives* d;
  const State* s;
  int n;
  std::vector<Vec3> turn;      // NIDC: D's rotation rows (base turned by them); empty otherwise
  std::vector<Vec3> shift;     // nidc_translation: D's translation rows; empty otherwise
  Vec6 H0m_qdot = Vec6::Zero();
  double links = 0.0;          // nidc_translation: the links' mass and sum_i m_i r0i
  Vec3 first_moment = Vec3::Zero();

  Eigen::Map<const RowMat6> gjm_dH0(int k) const { return Eigen::Map<const RowMat6>(d->dH0.data() + 36 * k); }
  // NIDC's change of dH0 for a base turned by r and moved by t (NIDCModel.augmented and
  // _translation_terms): Delta H0 - H0 Delta with Delta = diag(r x, r x), plus
  // [[0, m t x], [-m t x, t x S x + S x t x]], times x (6,).
  Vec6 augmentation_times(const Vec3& r, const Vec3& t, const Vec6& x) const {
    const Vec6 h = s->H0 * x;
    Vec6 turned;
    turned << r.cross(x.head<3>()), r.cross(x.tail<3>());
    Vec6 out = -(s->H0 * turned);
    out.head<3>() += r.cross(h.head<3>()) + links * t.cross(x.tail<3>());
    out.tail<3>() += r.cross(h.tail<3>()) - links * t.cross(x.head<3>()) +
                     t.cross(first_moment.cross(x.tail<3>())) + first_moment.cross(t.cross(x.tail<3>()));
    return out;
  }
  Vec3 turn_of(int k) const { return turn.empty() ? Vec3::Zero() : turn[k]; }
  Vec3 shift_of(int k) const { return shift.empty() ? Vec3::Zero() : shift[k]; }

  // dH0/dq_k x (6,).
  Vec6 dH0_times(int k, const Vec6& x) const {
    Vec6 out = gjm_dH0(k) * x;
    if (!turn.empty()) out += augmentation_times(turn[k], shift_of(k), x);
    return out;
  }
  // sum_k w_k dH0/dq_k (6, 6).
  Mat6 dH0_sum(const VecX& w) const {
    Mat6 out = Mat6::Zero();
    Vec3 r = Vec3::Zero(), t = Vec3::Zero();
    for (int k = 0; k < n; ++k) {
      out += w[k] * gjm_dH0(k);
      r += w[k] * turn_of(k);
      t += w[k] * shift_of(k);
    }
    if (!turn.empty())
      for (int c = 0; c < 6; ++c) out.col(c) += augmentation_times(r, t, Vec6::Unit(c));
    return out;
  }
  // dH0m/dq_k qdot (6,); NIDC adds Delta_k H0m qdot (and -[0; delta_k J_TS qdot]).
  Vec6 dH0m_qdot(int k) const {
    Vec6 out = d->dH0m_times(k, s->qdot);
    if (!turn.empty()) {
      out.head<3>() += turn[k].cross(H0m_qdot.head<3>());
      out.tail<3>() += turn[k].cross(H0m_qdot.tail<3>());
    }
    if (!shift.empty()) out.tail<3>() -= shift[k].cross(H0m_qdot.head<3>());
    return out;
  }
  // sum_k w_k dH0m/dq_k (6, n).
  Mat6X dH0m_sum(const VecX& w) const {
    Mat6X out = Mat6X::Zero(6, n);
    for (int k = 0; k < n; ++k) d->add_dH0m(k, w[k], out);
    if (!turn.empty()) {
      Vec3 r = Vec3::Zero();
      for (int k = 0; k < n; ++k) r += w[k] * turn[k];
      out.topRows<3>() += skew(r) * s->H0m.topRows<3>();
      out.bottomRows<3>() += skew(r) * s->H0m.bottomRows<3>();
    }
    if (!shift.empty()) {
      Vec3 r = Vec3::Zero();
      for (int k = 0; k < n; ++k) r += w[k] * shift[k];
      out.bottomRows<3>() -= skew(r) * s->H0m.topRows<3>();
    }
    return out;
  }
};

inline Partials gjm_partials(const Tree& t, const State& s, const Derivatives& d) { return Partials{&d, &s, t.n}; }

// NIDCModel.augmented: the partials with the base turned by D's rotation (and moved by its
// translation for nidc_translation, NIDCModel._translation_terms). D is (n, 6), row k = dx0/dq_k.
inline Partials nidc_partials(const Tree& t, const State& s, const Derivatives& d, const MatX& D, bool translation) {
  const int n = t.n;
  Partials p{&d, &s, n};
  p.H0m_qdot = s.H0m * s.qdot;
  for (int k = 0; k < n; ++k) p.turn.push_back(D.row(k).tail<3>().transpose());
  if (translation) {
    for (int b = 1; b <= n; ++b) {
      p.links += t.mass[b];
      p.first_moment += t.mass[b] * (s.kin.com[b] - s.kin.r0);
    }
    for (int k = 0; k < n; ++k) p.shift.push_back(D.row(k).head<3>().transpose());
  }
  return p;
}

// gjm_base.quadratic_form: z^T dH_k z for each k, z = [x0dot; qdot].
inline VecX quadratic_form(const State& s, const Partials& p, int n) {
  VecX out(n);
  for (int k = 0; k < n; ++k)
    out[k] = s.x0dot.dot(p.dH0_times(k, s.x0dot)) + 2.0 * s.x0dot.dot(p.dH0m_qdot(k)) + p.d->dHm_form(k, s.qdot);
  return out;
}

// NIDCModel.xdot0_sensitivity: dxdot0/dq_k = H0^-1 (dH0_k H0^-1 H0m - dH0m_k) qdot, rows k (n, 6).
inline MatX sensitivity(const State& s, const Partials& p, int n) {
  const Vec6 base_rate = s.H0_ldlt.solve(s.H0m * s.qdot);
  MatX out(n, 6);
  for (int k = 0; k < n; ++k)
    out.row(k) = s.H0_ldlt.solve(p.dH0_times(k, base_rate) - p.dH0m_qdot(k)).transpose();
  return out;
}

// UnderactuatedGJM / NIDCModel.joint_space and base_bias.
inline ModelResult underactuated(const Tree& t, const State& s, const Derivatives& d, Variant variant, const Vec6& F,
                                 const MatX& D) {
  const int n = t.n;
  const bool nidc = variant == Variant::nidc || variant == Variant::nidc_translation;
  const bool full = variant == Variant::standard_full_hdot || variant == Variant::standard_corrected;
  const Partials p = nidc ? nidc_partials(t, s, d, D, variant == Variant::nidc_translation) : gjm_partials(t, s, d);
  Mat6 H0dot;
  Mat6X H0mdot;
  if (full) {
    H0dot = d.H0dot, H0mdot = d.H0mdot;
  } else {  // sum_k dH/dq_k qdot_k: the base's rotation left out
    H0dot = p.dH0_sum(s.qdot);
    H0mdot = p.dH0m_sum(s.qdot);
  }  // Hmdot is the same either way: Hm does not depend on the base rotation
  Vec6 c0 = Vec6::Zero();
  if (variant == Variant::standard_corrected) c0.tail<3>() = s.x0dot.head<3>().cross(s.momentum_base.head<3>());
  VecX c_m = -0.5 * quadratic_form(s, p, n);
  if (nidc) c_m -= sensitivity(s, p, n) * s.momentum_base;
  ModelResult out;
  out.base_bias = H0dot * s.x0dot + H0mdot * s.qdot + c0 - F;
  out.c = H0mdot.transpose() * s.x0dot + d.Hmdot_times(s.qdot, s.qdot) + c_m -
          s.H0m.transpose() * s.H0_ldlt.solve(out.base_bias);
  return out;
}

// GeneralizedInertiaModel.joint_space and base_acceleration. With A = H0^-1 H0m,
// dH*/dq_k = dHm_k - dH0m_k^T A - A^T dH0m_k + A^T dH0_k A is only ever contracted with qdot:
// sum_k qdot_k dH*/dq_k uses the joint-only rates, and qdot^T dH*/dq_k qdot needs A qdot only.
inline ModelResult generalized(const Tree& t, const State& s, const Derivatives& d, Variant variant) {
  const int n = t.n;
  const Mat6X A = solve0(s, s.H0m);  // (6, n)
  const VecX& qd = s.qdot;
  const Vec6 Aqd = A * qd;
  Mat6 H0dot_joints = Mat6::Zero();
  Mat6X H0mdot_joints = Mat6X::Zero(6, n);
  VecX quad(n), amended(n), gyro(n);
  const bool momentum = variant != Variant::reduced;
  const Vec6 invM = momentum ? Vec6(s.H0_ldlt.solve(s.momentum_base)) : Vec6::Zero();
  for (int k = 0; k < n; ++k) {
    const Eigen::Map<const RowMat6> dH0(d.dH0.data() + 36 * k);
    const Vec6 dH0m_qd = d.dH0m_times(k, qd);
    quad[k] = d.dHm_form(k, qd) - 2.0 * Aqd.dot(dH0m_qd) + Aqd.dot(dH0 * Aqd);
    H0dot_joints += qd[k] * dH0;
    d.add_dH0m(k, qd[k], H0mdot_joints);
    if (momentum) {
      const Vec6 dH0invM = dH0 * invM;
      amended[k] = -dH0invM.dot(invM);
      gyro[k] = dH0m_qd.dot(invM) - dH0invM.dot(Aqd);
    }
  }
  ModelResult out;
  out.c = d.Hmdot_times(qd, qd) - H0mdot_joints.transpose() * Aqd - A.transpose() * (H0mdot_joints * qd) +
          A.transpose() * (H0dot_joints * Aqd) - 0.5 * quad;
  if (momentum) {
    const VecX rate = d.H0mdot.transpose() * invM - s.H0m.transpose() * s.H0_ldlt.solve(d.H0dot * invM);
    if (variant == Variant::momentum_mono) out.c -= 0.5 * amended;
    else if (variant == Variant::momentum_multi) out.c += rate;
    else out.c += rate - gyro + 0.5 * amended;
  }
  const Vec6 x0dot = momentum ? s.x0dot : Vec6(-Aqd);
  out.base_bias = d.H0dot * x0dot + d.H0mdot * qd;
  return out;
}

}  // namespace

ModelResult model_terms(const Tree& t, const State& s, const Derivatives& d, Variant variant, const Vec6& F,
                               const MatX& D) {
  if (variant >= Variant::reduced) return generalized(t, s, d, variant);
  return underactuated(t, s, d, variant, F, D);
}

MatX nidc_sensitivity(const Tree& t, const State& s, const Derivatives& d, const MatX& D, bool translation) {
  return sensitivity(s, nidc_partials(t, s, d, D, translation), t.n);
}

void local_base_acceleration(const Tree& t, const double* q, const double* v, const Vec6& xddot0, double* out) {
  Mat3 R;
  Vec3 p;
  Vec6 x0dot;
  base_state(t, q, v, R, p, x0dot);
  const Vec3 lin = t.free_base ? Vec3(v[0], v[1], v[2]) : Vec3(v[0], v[1], 0.0);
  const Vec3 w = t.free_base ? Vec3(v[3], v[4], v[5]) : Vec3(0.0, 0.0, v[2]);
  const Vec3& c = t.base_com;
  const Vec3 dw = R.transpose() * xddot0.tail<3>();
  const Vec3 dv = R.transpose() * xddot0.head<3>() - dw.cross(c) - w.cross(lin + w.cross(c));
  if (t.free_base) {
    Eigen::Map<Vec3>{out} = dv;
    Eigen::Map<Vec3>{out + 3} = dw;
  } else {
    out[0] = dv.x(), out[1] = dv.y(), out[2] = dw.z();
  }
}

// TreeSolver (tree_solve.hpp).

void forward_dynamics(const Tree& t, const State& s, const Derivatives& d, TreeSolver& solver, Variant variant,
                      const Vec6& F, const MatX& D, const double* tau, const double* Q_q, const double* q,
                      const double* v, int nv, double* a) {
  const int n = t.n, n_base = nv - n;
  const ModelResult r = model_terms(t, s, d, variant, F, D);
  VecX z(6 + n);
  z.head<6>().setZero();
  z.tail(n) = Eigen::Map<const VecX>(tau, n) + Eigen::Map<const VecX>(Q_q, n) - r.c;
  solver.factor(s);
  solver.solve(z.data());
  Eigen::Map<VecX> qddot(a + n_base, n);
  qddot = z.tail(n);
  const Vec6 xddot0 = -s.H0_ldlt.solve(s.H0m * qddot + r.base_bias);
  local_base_acceleration(t, q, v, xddot0, a);
}

TreeSolver::TreeSolver(const Tree& t) : N(6 + t.n), start(N + 1, 0), D(N) {
  for (int i = 0; i < N; ++i) {
    if (i >= 6)
      for (auto a = t.above[i - 6].rbegin(); a != t.above[i - 6].rend(); ++a) ancestor.push_back(6 + *a);
    for (int b = (i < 6 ? i : 6) - 1; b >= 0; --b) ancestor.push_back(b);
    start[i + 1] = static_cast<int>(ancestor.size());
  }
  value.resize(ancestor.size());
}

void TreeSolver::factor(const State& s) {
  for (int i = 0; i < N; ++i) {
    const int j = i - 6;
    D[i] = j < 0 ? s.H0(i, i) : s.S[j].dot(s.H0m.col(j));
    for (int m = start[i]; m < start[i + 1]; ++m) {
      const int a = ancestor[m];
      value[m] = j < 0 ? s.H0(i, a) : a < 6 ? s.H0m(a, j) : s.S[a - 6].dot(s.H0m.col(j));
    }
  }
  factor();
}

void TreeSolver::factor() {
  for (int k = N - 1; k >= 0; --k) {
    const int first = start[k], last = start[k + 1];
    for (int m = first; m < last; ++m) {
      const int i = ancestor[m];
      const double a = value[m] / D[k];
      D[i] -= a * value[m];
      double* row = value.data() + start[i] - (m + 1);  // row[m2] is H(i, ancestor[m2]) for m2 > m
      for (int m2 = m + 1; m2 < last; ++m2) row[m2] -= a * value[m2];
      value[m] = a;
    }
  }
}

void TreeSolver::solve(double* x) const {
  for (int k = N - 1; k >= 0; --k)
    for (int m = start[k]; m < start[k + 1]; ++m) x[ancestor[m]] -= value[m] * x[k];
  for (int k = 0; k < N; ++k) x[k] /= D[k];
  for (int k = 0; k < N; ++k)
    for (int m = start[k]; m < start[k + 1]; ++m) x[k] -= value[m] * x[ancestor[m]];
}

}  // namespace freefloat
