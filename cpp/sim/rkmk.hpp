// Explicit Runge-Kutta-Munthe-Kaas steps on a configuration space: the C++ twin of
// freefloat.dynamics.integrators (stages.py, lie.py, fixed_step.py, explicit_rkmk.py,
// adaptive.py), the same tableaus, dexp^-1 series and step-size control, so that both give the
// same numbers to round-off. Free of Pinocchio: the closed-chain loop integrates on R^n
// (euclidean_space) without Pinocchio's headers, half a gigabyte and seconds of its compile;
// lie_rk.hpp puts a Pinocchio model's configuration space under it.
#pragma once

#include <Eigen/Geometry>  // cross products of the se(3) chart correction

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "eigen_types.hpp"

namespace freefloat::sim {

using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
// f(q, v, a): generalized acceleration a (nv,) at (q, v), controls held.
using Dynamics = std::function<void(const Vec&, const Vec&, Vec&)>;

// ad_t u on se(3), twists [v; w]: [w_t x v_u + v_t x w_u; w_t x w_u].
inline Vec6 ad_se3(const Vec6& t, const Vec6& u) {
  Vec6 out;
  out.head<3>() = t.tail<3>().cross(u.head<3>()) + t.head<3>().cross(u.tail<3>());
  out.tail<3>() = t.tail<3>().cross(u.tail<3>());
  return out;
}

// The velocity rows of a configuration space whose chart is corrected: a free flyer's se(3)
// (size 6, [v; w]) or a planar joint's se(2) (size 3, [vx, vy, wz]); other rows are Euclidean.
struct ChartBlock {
  int row, size;
};

// A configuration space: nq coordinates, nv velocities, the blocks of its chart and its
// retraction out = q (+) theta (theta (nv,) a chart increment).
struct ConfigurationSpace {
  int nq, nv;
  std::vector<ChartBlock> blocks;
  std::function<void(const Vec& q, const Vec& theta, Vec& out)> integrate;
};

// R^n (plants/vector_space.py): q (+) theta = q + theta, no chart correction.
inline ConfigurationSpace euclidean_space(int n) {
  return {n, n, {}, [](const Vec& q, const Vec& theta, Vec& out) { out = q + theta; }};
}

// dexp^{-1}_{-theta}(V) = V + ad V / 2 + ad^2 V / 12 - ad^4 V / 720 (+ ad^6 V / 30240, degree 6).
class ChartCorrection {
 public:
  ChartCorrection(std::vector<ChartBlock> blocks, int degree) : degree_(degree), blocks_(std::move(blocks)) {}

  void apply(const Vec& theta, const Vec& velocity, Vec& out) const {
    out = velocity;
    for (const ChartBlock& b : blocks_) {
      if (b.size == 6) {
        const Vec6 t = theta.segment<6>(b.row), v = velocity.segment<6>(b.row);
        const Vec6 x1 = ad_se3(t, v), x2 = ad_se3(t, x1), x4 = ad_se3(t, ad_se3(t, x2));
        Vec6 r = v + 0.5 * x1 + x2 / 12.0 - x4 / 720.0;
        if (degree_ >= 6) r += ad_se3(t, ad_se3(t, x4)) / 30240.0;
        out.segment<6>(b.row) = r;
      } else {  // se(2) [vx, vy, wz], closed form (lie.py _dexpinv_se2)
        const double x = theta[b.row], y = theta[b.row + 1], w = theta[b.row + 2];
        const double a = velocity[b.row], bb = velocity[b.row + 1], c = velocity[b.row + 2];
        const double u1 = y * c - w * bb, u2 = w * a - x * c;
        double k = 1.0 / 12.0 + w * w / 720.0;
        if (degree_ >= 6) k += w * w * w * w / 30240.0;
        out[b.row] = a + 0.5 * u1 - w * u2 * k;
        out[b.row + 1] = bb + 0.5 * u2 + w * u1 * k;
      }
    }
  }

 private:
  int degree_;
  std::vector<ChartBlock> blocks_;
};

// An explicit tableau: rows[i] has i entries; b the weights; b_low an embedded lower order (or
// empty: fixed steps); the step-size control's exponent -1 / (lower order + 1).
struct Tableau {
  std::vector<std::vector<double>> rows;
  std::vector<double> b, b_low;
  int series_degree;  // dexp^-1 terms kept: ad^(order - 2), at least 4
  double error_exponent = -0.2;
};

inline Tableau rk3_tableau() {  // Kutta's 3rd order (explicit_rkmk.py)
  return {{{}, {0.5}, {-1.0, 2.0}}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {}, 4};
}

inline Tableau bs32_tableau() {  // Bogacki-Shampine 3(2), first same as last (adaptive.py)
  return {{{}, {0.5}, {0.0, 0.75}, {2.0 / 9, 1.0 / 3, 4.0 / 9}},
          {2.0 / 9, 1.0 / 3, 4.0 / 9, 0.0},
          {7.0 / 24, 1.0 / 4, 1.0 / 3, 1.0 / 8},
          4,
          -1.0 / 3};
}

inline Tableau rk4_tableau() {
  return {{{}, {0.5}, {0.0, 0.5}, {0.0, 0.0, 1.0}}, {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6}, {}, 4};
}

inline Tableau rk6_tableau() {  // Butcher's 7-stage 6th order (explicit_rkmk.py)
  return {{{},
           {1.0 / 3},
           {0.0, 2.0 / 3},
           {1.0 / 12, 1.0 / 3, -1.0 / 12},
           {-1.0 / 16, 9.0 / 8, -3.0 / 16, -3.0 / 8},
           {0.0, 9.0 / 8, -3.0 / 8, -3.0 / 4, 1.0 / 2},
           {9.0 / 44, -9.0 / 11, 63.0 / 44, 18.0 / 11, 0.0, -16.0 / 11}},
          {11.0 / 120, 0.0, 27.0 / 40, 27.0 / 40, -4.0 / 15, -4.0 / 15, 11.0 / 120},
          {},
          4};
}

inline Tableau rk8_tableau() {  // Cooper-Verner 11-stage 8th order (explicit_rkmk.py)
  const double r = std::sqrt(21.0);
  return {{{},
           {1.0 / 2},
           {1.0 / 4, 1.0 / 4},
           {1.0 / 7, -(7 + 3 * r) / 98, (21 + 5 * r) / 49},
           {(11 + r) / 84, 0.0, (18 + 4 * r) / 63, (21 - r) / 252},
           {(5 + r) / 48, 0.0, (9 + r) / 36, (-231 + 14 * r) / 360, (63 - 7 * r) / 80},
           {(10 - r) / 42, 0.0, (-432 + 92 * r) / 315, (633 - 145 * r) / 90, (-504 + 115 * r) / 70,
            (63 - 13 * r) / 35},
           {1.0 / 14, 0.0, 0.0, 0.0, (14 - 3 * r) / 126, (13 - 3 * r) / 63, 1.0 / 9},
           {1.0 / 32, 0.0, 0.0, 0.0, (91 - 21 * r) / 576, 11.0 / 72, -(385 + 75 * r) / 1152, (63 + 13 * r) / 128},
           {1.0 / 14, 0.0, 0.0, 0.0, 1.0 / 9, -(733 + 147 * r) / 2205, (515 + 111 * r) / 504, -(51 + 11 * r) / 56,
            (132 + 28 * r) / 245},
           {0.0, 0.0, 0.0, 0.0, (-42 + 7 * r) / 18, (-18 + 28 * r) / 45, -(273 + 53 * r) / 72, (301 + 53 * r) / 72,
            (28 - 28 * r) / 45, (49 - 7 * r) / 18}},
          {1.0 / 20, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 49.0 / 180, 16.0 / 45, 49.0 / 180, 1.0 / 20},
          {},
          6};
}

inline Tableau dopri5_tableau() {  // Dormand-Prince 5(4) (adaptive.py)
  return {{{},
           {1.0 / 5},
           {3.0 / 40, 9.0 / 40},
           {44.0 / 45, -56.0 / 15, 32.0 / 9},
           {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
           {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
           {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}},
          {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84, 0.0},
          {5179.0 / 57600, 0.0, 7571.0 / 16695, 393.0 / 640, -92097.0 / 339200, 187.0 / 2100, 1.0 / 40},
          4,
          -0.2};
}

// The names LieIntegrator takes: freefloat.dynamics.integrators.INTEGRATORS' compiled entries
// (exported as _sim.INTEGRATORS; tests/test_compiled.py checks the two lists agree).
inline const std::vector<std::string>& integrator_names() {
  static const std::vector<std::string> names{"euler", "rkmk3", "rkmk4", "rk4_naive", "rkmk6", "rkmk8", "dopri5",
                                              "bs32"};
  return names;
}

// f(q, v, a, n): the accelerations a[l] (nv,) at (q[l], v[l]) of n states at once (l < n), controls
// held; lockstep.hpp's evaluates them in the lanes of the dynamics kernel.
using LaneDynamics = std::function<void(const Vec* const* q, const Vec* const* v, Vec* const* a, int n)>;

// One integrator of the registry by name, advancing (q, v) on `space` over a control period; a
// fixed-step one also advances up to `lanes` states together, their dynamics evaluated at once
// (advance_lanes), each state's numbers those of advance() to round-off.
class RkmkIntegrator {
 public:
  RkmkIntegrator(ConfigurationSpace space, const std::string& name, int substeps, double rtol, double atol,
                 int max_steps = 100000, int lanes = 1)
      : space_(std::move(space)), name_(name), substeps_(substeps), rtol_(rtol), atol_(atol), max_steps_(max_steps),
        chart_(space_.blocks, name == "rkmk8" ? 6 : 4) {
    if (name == "rkmk3") tableau_ = rk3_tableau();
    else if (name == "rkmk4" || name == "rk4_naive") tableau_ = rk4_tableau();
    else if (name == "rkmk6") tableau_ = rk6_tableau();
    else if (name == "rkmk8") tableau_ = rk8_tableau();
    else if (name == "dopri5") tableau_ = dopri5_tableau();
    else if (name == "bs32") tableau_ = bs32_tableau();
    else if (name != "euler") throw std::invalid_argument("unknown integrator '" + name + "'");
    if (substeps < 1) throw std::invalid_argument("substeps must be >= 1");
    if (lanes < 1 || lanes > kMaxLanes) throw std::invalid_argument("lanes must be 1 to " + std::to_string(kMaxLanes));
    const size_t s = std::max<size_t>(tableau_.b.size(), 1);
    lane_.resize(lanes);
    for (Lane& L : lane_) {
      L.K.resize(s, space_.nv);
      L.A.resize(s, space_.nv);
      L.theta.resize(space_.nv);
      L.vel.resize(space_.nv);
      L.k.resize(space_.nv);
      L.qs.resize(space_.nq);
      L.a.resize(space_.nv);
    }
  }

  // Dynamics evaluations: of each state, in advance_lanes().
  long evaluations() const { return calls_; }
  // Whether the step size is fixed (advance_lanes() takes this integrator).
  bool fixed_step() const { return tableau_.b_low.empty(); }
  int lanes() const { return static_cast<int>(lane_.size()); }

  // Forget the adaptive step size (a new run starts from its first guess, the whole period).
  void restart() { h_ = 0.0; }

  // (q, v) <- state after `duration` s.
  void advance(const Dynamics& f, Vec& q, Vec& v, double duration) {
    Vec* qs[1] = {&q};
    Vec* vs[1] = {&v};
    const LaneDynamics one = [&f](const Vec* const* x, const Vec* const* xd, Vec* const* a, int) { f(*x[0], *xd[0], *a[0]); };
    if (!fixed_step()) return adaptive(one, q, v, duration);
    advance_lanes(one, qs, vs, 1, duration);
  }

  // (q[l], v[l]) <- state l after `duration` s, for n <= lanes() states, a fixed-step method.
  void advance_lanes(const LaneDynamics& f, Vec* const* q, Vec* const* v, int n, double duration) {
    if (!fixed_step()) throw std::invalid_argument(name_ + " has no fixed step: it advances one state at a time");
    if (n < 1 || n > lanes()) throw std::invalid_argument("advance_lanes: 1 to " + std::to_string(lanes()) + " states");
    const double h = duration / substeps_;
    for (int i = 0; i < substeps_; ++i) {
      if (name_ == "euler") {
        evaluate(f, q, v, n, 0);
        for (int l = 0; l < n; ++l) {
          Lane& L = lane_[l];
          *v[l] += h * L.a;
          L.theta = h * *v[l];
          space_.integrate(*q[l], L.theta, L.qs);
          *q[l] = L.qs;
        }
      } else {
        stages(f, q, v, n, h, false);
        for (int l = 0; l < n; ++l) {
          Lane& L = lane_[l];
          combine(L, tableau_.b, h, L.theta, L.vel);
          space_.integrate(*q[l], L.theta, L.qs);
          *q[l] = L.qs;
          *v[l] += L.vel;
        }
      }
    }
  }

 private:
  // One state's stages: chart velocities K, accelerations A, and scratch (chart increment, stage
  // velocity, chart velocity, stage q, acceleration).
  struct Lane {
    Mat K, A;
    Vec theta, vel, k, qs, a;
  };

  // Each lane's acceleration at (q[l], v[l]) into its a, then A's row `row`.
  void evaluate(const LaneDynamics& f, const Vec* const* q, const Vec* const* v, int n, int row) {
    Vec* a[kMaxLanes];
    for (int l = 0; l < n; ++l) a[l] = &lane_[l].a;
    f(q, v, a, n);
    for (int l = 0; l < n; ++l) lane_[l].A.row(row) = lane_[l].a.transpose();
    ++calls_;
  }

  // Stage chart velocities K and accelerations A of n states; the first stage's acceleration is
  // reused when `first_known` (FSAL).
  void stages(const LaneDynamics& f, const Vec* const* q, const Vec* const* v, int n, double h, bool first_known) {
    const size_t s = tableau_.rows.size();
    for (int l = 0; l < n; ++l) lane_[l].K.row(0) = v[l]->transpose();
    if (!first_known) evaluate(f, q, v, n, 0);
    const bool correct = name_ != "rk4_naive";
    const Vec* qs[kMaxLanes];
    const Vec* vels[kMaxLanes];
    for (size_t i = 1; i < s; ++i) {
      for (int l = 0; l < n; ++l) {
        Lane& L = lane_[l];
        combine(L, tableau_.rows[i], h, L.theta, L.vel);
        L.vel += *v[l];
        if (correct) chart_.apply(L.theta, L.vel, L.k);
        else L.k = L.vel;
        L.K.row(i) = L.k.transpose();
        space_.integrate(*q[l], L.theta, L.qs);
        qs[l] = &L.qs;
        vels[l] = &L.vel;
      }
      evaluate(f, qs, vels, n, static_cast<int>(i));
    }
  }

  // theta = h sum_j w_j K_j, dv = h sum_j w_j A_j of lane L.
  static void combine(const Lane& L, const std::vector<double>& w, double h, Vec& theta, Vec& dv) {
    theta.setZero();
    dv.setZero();
    for (size_t j = 0; j < w.size(); ++j) {
      if (w[j] == 0.0) continue;
      theta += (h * w[j]) * L.K.row(j).transpose();
      dv += (h * w[j]) * L.A.row(j).transpose();
    }
  }

  void adaptive(const LaneDynamics& f, Vec& q, Vec& v, double duration) {
    Lane& L = lane_[0];
    const Vec* qs[1] = {&q};
    const Vec* vs[1] = {&v};
    double t = 0.0, h = h_ > 0.0 ? h_ : duration;
    bool fsal = false;
    const size_t s = tableau_.rows.size();
    std::vector<double> db(s);
    for (size_t j = 0; j < s; ++j) db[j] = tableau_.b[j] - tableau_.b_low[j];
    Vec err_theta(space_.nv), err_v(space_.nv);
    for (int n = 0; n < max_steps_; ++n) {
      if (t >= duration * (1.0 - 1e-12)) return;
      const double h_try = std::min(h, duration - t);
      stages(f, qs, vs, 1, h_try, fsal);
      combine(L, db, h_try, err_theta, err_v);
      combine(L, tableau_.b, h_try, L.theta, L.vel);
      const Vec v_new = v + L.vel;
      double sum = 0.0;
      for (int i = 0; i < space_.nv; ++i) {
        const double sv = atol_ + rtol_ * std::max(std::abs(v[i]), std::abs(v_new[i]));
        const double st = atol_ + rtol_ * std::abs(L.theta[i]);
        sum += (err_theta[i] / st) * (err_theta[i] / st) + (err_v[i] / sv) * (err_v[i] / sv);
      }
      const double err = std::sqrt(sum / (2.0 * space_.nv));
      // err NaN (a stage left the dynamics' domain: the step was far too long): shrink 10x
      const double factor = err > 0.0 ? 0.9 * std::pow(err, tableau_.error_exponent) : (err == 0.0 ? 5.0 : 0.1);
      if (err <= 1.0) {
        space_.integrate(q, L.theta, L.qs);
        q = L.qs;
        v = v_new;
        L.A.row(0) = L.A.row(s - 1);
        fsal = true;
        t += h_try;
        ++accepted_;
        h = h_try * std::min(5.0, std::max(0.2, factor));
        h_ = h;
      } else {
        ++rejected_;
        fsal = true;  // the first stage is the same state: keep its acceleration
        h = h_try * std::max(0.1, factor);
      }
    }
    throw std::overflow_error(name_ + ": " + std::to_string(max_steps_) + " steps did not cover " +
                             std::to_string(duration) + " s (last step " + std::to_string(h) + " s)");
  }

  static constexpr int kMaxLanes = 8;
  ConfigurationSpace space_;
  std::string name_;
  int substeps_;
  double rtol_, atol_;
  int max_steps_;
  ChartCorrection chart_;
  Tableau tableau_;
  std::vector<Lane> lane_;
  long calls_ = 0, accepted_ = 0, rejected_ = 0;
  double h_ = 0.0;

 public:
  long accepted() const { return accepted_; }
  long rejected() const { return rejected_; }
};

}  // namespace freefloat::sim
