// The compiled loops' chunk of control periods (the C++ side of simulation._run_compiled): the
// robot loop (loop.hpp) and the closed-chain loop (chain_loop.hpp) run their periods through it.
#pragma once

#include <stdexcept>
#include <string>

namespace freefloat::sim {

// Periods from `k` (advanced by `one_period`'s step) to `last` (exclusive), or until a period
// that records finds no free row in a chunk of `capacity` rows. `one_period(t, records, row)`
// does one period at time t (the law, the telemetry row `row++` when `records`, the step) and
// throws std::overflow_error with the Python loop's message on a blow-up: the chunk stops there,
// the message in `error`. Returns the rows written from `row`.
template <typename OnePeriod>
int run_periods(const long& k, long last, double start, double period, int record_every, int capacity, int row,
                std::string& error, OnePeriod&& one_period) {
  const int first_row = row;
  while (k < last) {
    const double t = start + k * period;
    const bool records = k % record_every == 0;
    if (records && row == capacity) break;
    try {
      one_period(t, records, row);
    } catch (const std::overflow_error& stop) {
      error = stop.what();
      break;
    }
  }
  return row - first_row;
}

}  // namespace freefloat::sim
