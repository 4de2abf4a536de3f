// What the two binding units of freefloat.dynamics._sim share (sim.cpp binds the robot loop and
// the module, chains.cpp the closed-chain loop; they compile in parallel): array
// conversions, the telemetry chunks' checks and the chunk runner.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "py_arrays.hpp"
#include "sim/model_arrays.hpp"

namespace freefloat::sim::py_sim {

namespace py = pybind11;
using freefloat::py_arrays::Array;
using freefloat::py_arrays::checked;
using OutArray = py::array_t<double, py::array::c_style>;

inline Eigen::VectorXd vec(const Array& a, py::ssize_t size, const char* name) {
  return Eigen::Map<const Eigen::VectorXd>(checked(a, size, name), size);
}

inline py::array_t<double> out(const Eigen::VectorXd& x) {
  py::array_t<double> r(x.size());
  Eigen::Map<Eigen::VectorXd>(r.mutable_data(), x.size()) = x;
  return r;
}

inline py::array_t<double> out(const Eigen::MatrixXd& x) {
  py::array_t<double> r({x.rows(), x.cols()});
  Eigen::Map<freefloat::py_arrays::RowMat>(r.mutable_data(), x.rows(), x.cols()) = x;
  return r;
}

inline py::object maybe(const std::optional<Eigen::VectorXd>& x) {
  return x ? py::object(out(*x)) : py::object(py::none());
}

// The arrays of compiled._model_arrays, checked against the joints' and frames' counts (the
// rest is checked as the model is built).
inline ModelArrays arrays_of(const std::vector<int>& parent, const std::vector<std::string>& kind,
                             const std::vector<std::string>& name, const Array& subspace, const Array& placement,
                             const Array& mass, const Array& lever, const Array& rotational, const Array& armature,
                             const Array& gravity, const std::vector<int>& frame_parent,
                             const Array& frame_placement) {
  const py::ssize_t n = static_cast<py::ssize_t>(parent.size()), f = static_cast<py::ssize_t>(frame_parent.size());
  return ModelArrays{parent, kind, name, checked(subspace, 6 * n, "subspace"), checked(placement, 16 * n, "placement"),
                     checked(mass, n, "mass"), checked(lever, 3 * n, "lever"), checked(rotational, 9 * n, "rotational"),
                     armature.data(), static_cast<long>(armature.size()), checked(gravity, 3, "gravity"), frame_parent,
                     checked(frame_placement, 16 * f, "frame_placement")};
}

// The C-contiguous float64 arrays of one telemetry chunk, field i holding rows * widths[i]
// numbers: (rows, their data). `what` names the telemetry class in errors.
inline std::pair<int, std::vector<double*>> fields_of(py::tuple arrays, const std::vector<long>& widths, const char* what) {
  if (arrays.size() != widths.size())
    throw std::invalid_argument(std::string("telemetry: expected the ") + std::to_string(widths.size()) +
                                " arrays of " + what);
  const int rows = static_cast<int>(arrays[0].cast<OutArray>().size());
  std::vector<double*> data;
  for (size_t i = 0; i < widths.size(); ++i) {
    py::object item = arrays[i];
    if (!py::isinstance<OutArray>(item) || !item.cast<py::array>().dtype().is(py::dtype::of<double>()) ||
        !(item.cast<py::array>().flags() & py::array::c_style))
      throw std::invalid_argument("telemetry field " + std::to_string(i) + ": expected a C-contiguous float64 array");
    OutArray a = item.cast<OutArray>();
    if (a.size() != rows * widths[i])
      throw std::invalid_argument("telemetry field " + std::to_string(i) + ": expected " +
                                  std::to_string(rows * widths[i]) + " numbers, got " + std::to_string(a.size()));
    data.push_back(a.mutable_data());
  }
  return {rows, data};
}

// run() of either compiled loop on a chunk, the GIL released: (rows written from `row`, the
// blow-up message or None).
template <typename Loop, typename Chunk>
py::tuple run_chunk(Loop& loop, long last, Chunk rows, int row) {
  if (row < 0 || row > rows.rows) throw std::invalid_argument("row out of range");
  std::string error;
  int written;
  {
    py::gil_scoped_release release;
    written = loop.run(last, rows, row, error);
  }
  return py::make_tuple(written, error.empty() ? py::object(py::none()) : py::object(py::str(error)));
}

}  // namespace freefloat::sim::py_sim

namespace freefloat::sim {
void bind_chain(pybind11::module_& m);  // chains.cpp
}
