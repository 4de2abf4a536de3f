// The simulation loop of freefloat.dynamics.simulation.run_plant for a closed chain by Orsino's
// coupling (freefloat.dynamics.plants.CoupledChainPlant), in C++: zero-order-hold control periods
// (or the law at every stage), eq 129 with Baumgarte as the plant (chains/mechanism.hpp), an integrator of
// rkmk.hpp on the Euclidean coordinates q = [q#; q°], the platform control of
// freefloat.parallel.sliding_mode.PlatformControl (computed torque, eq 190, or sliding mode,
// eq 153) on a nominal model, and the telemetry row of plant_periods.PlantPeriods. Declarations:
// the loop and the law are defined in chain_loop.cpp.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "chains/mechanism.hpp"
#include "rkmk.hpp"

namespace freefloat::sim {

// platform_control.CircleReference: q#_d = center + radius (cos(rate t) e_a + sin(rate t) e_b).
struct Circle {
  DVec center;
  double radius = 0.0, rate = 0.0;
  int a = 0, b = 1;

  void at(double t, DVec& q, DVec& qd, DVec& qdd) const;
};

// sliding_mode.PlatformControl.law on the nominal `model`: computed torque (no gains) or sliding
// mode with eq 167's gains n, T, n_ij and sign or tanh(100 s).
struct PlatformLaw {
  Mechanism model;
  Circle reference;
  double lam = 0.0;
  int every = 1;  // evaluated every this many control periods, held in between (dynamics.sampled.Sampled)
  bool sliding = false, sign = false;
  DVec n;
  DMat T;
  std::vector<std::pair<int, int>> pairs;
  std::vector<DVec> n_ij;

  // Efforts (k) at time t for the measured state (q, qd) (n_q).
  DVec efforts(double t, const DVec& q, const DVec& qd);

  // The reference q#_d (p) at time t.
  DVec target(double t) const;
};

// Telemetry arrays of one chunk, row-major; shapes as in freefloat.dynamics.telemetry.PlantTelemetry.
struct ChainRows {
  int rows = 0;
  double *t, *q, *v, *efforts, *reference, *drift, *orientation_drift;
};

class ChainSimulation {
 public:
  ChainSimulation(Mechanism plant, double baumgarte, double max_drift, const std::string& integrator, int substeps,
                  double rtol, double atol, double control_period, double start_time, int record_every,
                  bool per_stage);

  void set_law(PlatformLaw law);
  bool has_law() const { return law_.has_value(); }

  void hold(const DVec& u) { u_ = u; }

  void set_state(const DVec& q, const DVec& v, long period);

  const DVec& q() const { return q_; }
  const DVec& v() const { return v_; }
  long period() const { return k_; }
  long evaluations() const { return integrator_.evaluations(); }

  // The law's efforts at (t, q, v), outside of any run.
  DVec law_efforts(double t, const DVec& q, const DVec& v);

  // One control period from the current state, efforts held (or the law per stage). Throws
  // std::overflow_error with the Python loop's message on a blow-up (the state stays).
  void step_period();

  // Runs until period `last` (exclusive) or until `out` has no free row for a period that records;
  // writes rows from `row`. Returns the rows written; on a blow-up stops there with the message in `error`.
  int run(long last, ChainRows& out, int row, std::string& error);

  // Row `row` of `out` at the current state and time with the efforts held; the reference from
  // `reference` if given, else from the compiled law (or left as it is: NaN).
  void record(ChainRows& out, int row, const DVec* reference);

 private:
  // The closure's residuals at q: (max |position rows|, max |orientation rows|).
  std::pair<double, double> drift(const DVec& q);

  // One control period from time t; throws std::overflow_error on a blow-up (the state stays).
  void step(double t);

  Mechanism plant_;
  double baumgarte_, max_drift_;
  bool per_stage_;
  RkmkIntegrator integrator_;
  double period_, start_;
  int record_every_;
  Dynamics dynamics_;
  std::optional<PlatformLaw> law_;
  long k_ = 0;
  DVec q_, v_, u_, qn_, vn_;
  std::pair<double, double> drift_{0.0, 0.0};
};

}  // namespace freefloat::sim
