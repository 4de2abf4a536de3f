// The NumPy arrays the compiled modules take (C order, converted to double), with their size
// checked against what the call needs.
#pragma once

#include <pybind11/numpy.h>

#include <stdexcept>
#include <string>

namespace freefloat::py_arrays {

using Array = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

// The data of `a` when it holds `size` numbers; std::invalid_argument (ValueError) naming it otherwise.
inline const double* checked(const Array& a, pybind11::ssize_t size, const char* name) {
  if (a.size() != size)
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(size) + " numbers, got " +
                                std::to_string(a.size()));
  return a.data();
}

}  // namespace freefloat::py_arrays
