// The NumPy arrays the compiled modules take (C order, converted to double), with their size
// checked against what the call needs, and the new C-order arrays they return.
#pragma once

#include <pybind11/numpy.h>

#include <Eigen/Core>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace freefloat::py_arrays {

using Array = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;
using IntArray = pybind11::array_t<long long, pybind11::array::c_style | pybind11::array::forcecast>;

// The data of `a` when it holds `size` numbers; std::invalid_argument (ValueError) naming it otherwise.
inline const double* checked(const Array& a, pybind11::ssize_t size, const char* name) {
  if (a.size() != size)
    throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(size) + " numbers, got " +
                                std::to_string(a.size()));
  return a.data();
}

using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A new array of `shape` holding a copy of `data`.
inline pybind11::array_t<double> copy_out(std::vector<pybind11::ssize_t> shape, const double* data) {
  pybind11::array_t<double> out(shape);
  std::memcpy(out.mutable_data(), data, sizeof(double) * out.size());
  return out;
}

template <typename M>
pybind11::array_t<double> matrix_out(const M& m) {  // row-major copy of any Eigen matrix
  pybind11::array_t<double> out({static_cast<pybind11::ssize_t>(m.rows()), static_cast<pybind11::ssize_t>(m.cols())});
  Eigen::Map<RowMat>(out.mutable_data(), m.rows(), m.cols()) = m;
  return out;
}

template <typename V>
pybind11::array_t<double> vector_out(const V& x) {
  return copy_out({static_cast<pybind11::ssize_t>(x.size())}, x.data());
}

}  // namespace freefloat::py_arrays
