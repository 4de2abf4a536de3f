// The closed-chain loop and its platform law (chain_loop.hpp): ChainSimulation's periods, steps
// and telemetry rows, PlatformLaw's efforts, on the plant of chains/mechanism.hpp.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "chain_loop.hpp"
#include "periods.hpp"

namespace freefloat::sim {

void Circle::at(double t, DVec& q, DVec& qd, DVec& qdd) const {
  const double c = std::cos(rate * t), s = std::sin(rate * t), r = radius, w = rate;
  q = center;
  qd = DVec::Zero(center.size());
  qdd = DVec::Zero(center.size());
  q[a] += r * c;
  q[b] += r * s;
  qd[a] = -r * w * s;
  qd[b] = r * w * c;
  qdd[a] = -r * w * w * c;
  qdd[b] = -r * w * w * s;
}

DVec PlatformLaw::efforts(double t, const DVec& q, const DVec& qd) {
  const int p = model.p;
  DVec q_d, qd_d, qdd_d;
  reference.at(t, q_d, qd_d, qdd_d);
  const DVec e = q_d - q.head(p), edot = qd_d - qd.head(p);
  // platform.platform_dynamics at (q, qd#): H, v_M, g_M, B
  DVec residual, b, v, g;
  DMat A, M;
  model.closure(q.data(), residual, A);
  const Eigen::PartialPivLU<DMat> lu = model.passive_lu(A);
  const DMat C = model.velocity_map(A, lu);
  const DVec qd_full = C * qd.head(p);
  model.dynamics(qd_full.data(), b, M, v, g);
  DVec c = DVec::Zero(model.n_q);
  c.tail(model.n_q - p) = lu.solve(b);
  const DMat CT = C.transpose();
  const DMat H = CT * M * C;
  const DVec h = CT * (M * c + v) + CT * g;
  const DMat B = CT * model.U;
  DVec acceleration;
  if (!sliding) {
    acceleration = qdd_d + 2.0 * lam * edot + lam * lam * e;
  } else {
    const DVec s = -(edot + lam * e), sigma = qdd_d + lam * edot;
    DVec k = n + T * sigma.cwiseAbs();
    for (size_t i = 0; i < pairs.size(); ++i)
      k += n_ij[i] * std::abs(qd[pairs[i].first]) * std::abs(qd[pairs[i].second]);
    DVec sw(p);
    for (int i = 0; i < p; ++i) sw[i] = sign ? double((s[i] > 0) - (s[i] < 0)) : std::tanh(100.0 * s[i]);
    acceleration = sigma - k.cwiseProduct(sw);
  }
  return B.partialPivLu().solve(h + H * acceleration);
}

DVec PlatformLaw::target(double t) const {
  DVec q, qd, qdd;
  reference.at(t, q, qd, qdd);
  return q;
}

ChainSimulation::ChainSimulation(Mechanism plant, double baumgarte, double max_drift, const std::string& integrator,
                                 int substeps, double rtol, double atol, double control_period, double start_time,
                                 int record_every, bool per_stage)
    : plant_(std::move(plant)), baumgarte_(baumgarte), max_drift_(max_drift), per_stage_(per_stage),
      integrator_(euclidean_space(plant_.n_q + (per_stage ? 1 : 0)), integrator, substeps, rtol, atol),
      period_(control_period), start_(start_time), record_every_(record_every) {
  const int n = plant_.n_q;
  q_ = DVec::Zero(n);
  v_ = DVec::Zero(n);
  u_ = DVec::Zero(plant_.U.cols());
  dynamics_ = [this, n](const Vec& q, const Vec& v, Vec& a) {
    if (!per_stage_) {
      a = plant_.forward(q.data(), v.data(), u_.data(), baumgarte_);
      return;
    }
    const DVec qs = q.head(n), vs = v.head(n);  // [q; t], [v; 1]
    const DVec u = law_->efforts(q[n], qs, vs);
    a.resize(n + 1);
    a.head(n) = plant_.forward(qs.data(), vs.data(), u.data(), baumgarte_);
    a[n] = 0.0;
  };
}

void ChainSimulation::set_law(PlatformLaw law) {
  if (law.model.n_q != plant_.n_q || law.model.U.cols() != plant_.U.cols())
    throw std::invalid_argument("the controller's model and the plant differ in size");
  law_ = std::move(law);
}

void ChainSimulation::set_state(const DVec& q, const DVec& v, long period) {
  integrator_.restart();
  q_ = q;
  v_ = v;
  k_ = period;
  drift_ = drift(q_);
}

DVec ChainSimulation::law_efforts(double t, const DVec& q, const DVec& v) { return law_->efforts(t, q, v); }

void ChainSimulation::step_period() { step(start_ + k_ * period_); }

int ChainSimulation::run(long last, ChainRows& out, int row, std::string& error) {
  return run_periods(k_, last, start_, period_, record_every_, out.rows, row, error,
                     [&](double t, bool records, int& r) {
                       try {
                         if (law_ && k_ % law_->every == 0) u_ = law_->efforts(t, q_, v_);
                         if (records) record(out, r++, nullptr);
                         step(t);
                       } catch (const MechanismError& singular) {
                         char when[96];
                         std::snprintf(when, sizeof when,
                                       "at t = %.6g s (step %ld): singular pose, eq 129 has no solution: ", t, k_ + 1);
                         throw std::overflow_error(when + std::string(singular.what()));
                       }
                     });
}

void ChainSimulation::record(ChainRows& out, int row, const DVec* reference) {
  const int n = plant_.n_q, k = static_cast<int>(u_.size());
  const double t = start_ + k_ * period_;
  out.t[row] = t;
  Eigen::Map<DVec>(out.q + n * row, n) = q_;
  Eigen::Map<DVec>(out.v + n * row, n) = v_;
  Eigen::Map<DVec>(out.efforts + k * row, k) = u_;
  if (reference != nullptr) {
    Eigen::Map<DVec>(out.reference + reference->size() * row, reference->size()) = *reference;
  } else if (law_) {
    const DVec target = law_->target(t);
    Eigen::Map<DVec>(out.reference + target.size() * row, target.size()) = target;
  }
  out.drift[row] = drift_.first;
  out.orientation_drift[row] = drift_.second;
}

std::pair<double, double> ChainSimulation::drift(const DVec& q) {
  DVec residual;
  DMat A;
  plant_.closure(q.data(), residual, A);
  const double position = plant_.m_lin ? residual.head(plant_.m_lin).cwiseAbs().maxCoeff() : 0.0;
  const double orientation = plant_.m_ang ? residual.tail(plant_.m_ang).cwiseAbs().maxCoeff() : 0.0;
  return {position, orientation};
}

void ChainSimulation::step(double t) {
  const int n = plant_.n_q;
  if (per_stage_) {
    qn_.resize(n + 1);
    vn_.resize(n + 1);
    qn_ << q_, t;
    vn_ << v_, 1.0;
  } else {
    qn_ = q_;
    vn_ = v_;
  }
  integrator_.advance(dynamics_, qn_, vn_, period_);
  const double t_end = t + period_;
  if (!(qn_.allFinite() && vn_.allFinite())) {
    char text[128];
    std::snprintf(text, sizeof text, "the state is not finite at t = %.6g s (step %ld)", t_end, k_ + 1);
    throw std::overflow_error(text);
  }
  const DVec q = qn_.head(n);
  const auto next = drift(q);
  if (!(std::max(next.first, next.second) <= max_drift_)) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "loop-closure residual %.3g m (orientation %.3g rad) at t = %.6g s (step %ld): the mechanism came "
                  "apart", next.first, next.second, t_end, k_ + 1);
    throw std::overflow_error(text);
  }
  q_ = q;
  v_ = vn_.head(n);
  drift_ = next;
  ++k_;
}

}  // namespace freefloat::sim
