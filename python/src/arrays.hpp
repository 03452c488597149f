// Arrays between numpy and the core without copies where the memory can be shared: results
// hand their Eigen/std::vector storage to numpy (a capsule owns it and frees it with the last
// array), inputs are read in place through Eigen maps.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstddef>
#include <initializer_list>
#include <utility>
#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::python {

namespace nb = nanobind;

template <typename T>
using Array1 = nb::ndarray<nb::numpy, T, nb::ndim<1>>;
using Array2 = nb::ndarray<nb::numpy, double, nb::ndim<2>, nb::f_contig>;
// Inputs: 1-D float64 (contiguous), 2-D float64 in column order (Eigen's), int32 indices.
using InVector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using InMatrix = nb::ndarray<const double, nb::ndim<2>, nb::f_contig, nb::device::cpu>;
using InIndex = nb::ndarray<const int, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

// Moves `owned` to the heap and returns a numpy view of its `size` elements at data(owned).
template <typename Owned, typename T>
nb::ndarray<nb::numpy, T, nb::ndim<1>> adopt(Owned&& owned, T* (*data)(Owned&), std::size_t size) {
  auto* heap = new Owned(std::move(owned));
  nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<Owned*>(p); });
  return nb::ndarray<nb::numpy, T, nb::ndim<1>>(data(*heap), {size}, owner);
}

inline Array1<double> toNumpy(Vector&& v) {
  const auto n = static_cast<std::size_t>(v.size());
  return adopt<Vector, double>(
      std::move(v), [](Vector& o) { return o.data(); }, n);
}

template <typename T>
Array1<T> toNumpy(std::vector<T>&& v) {
  const std::size_t n = v.size();
  return adopt<std::vector<T>, T>(
      std::move(v), [](std::vector<T>& o) { return o.data(); }, n);
}

// A column-major matrix as an F-ordered numpy array sharing its memory.
inline Array2 toNumpy(DenseMatrix&& m) {
  auto* heap = new DenseMatrix(std::move(m));
  nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<DenseMatrix*>(p); });
  const std::size_t shape[2] = {static_cast<std::size_t>(heap->rows()),
                                static_cast<std::size_t>(heap->cols())};
  return Array2(heap->data(), 2, shape, owner);
}

// A flat vector as a C-ordered array of the given shape (the product of which is v.size()).
inline nb::ndarray<nb::numpy, double> toNumpy(std::vector<double>&& v,
                                              std::initializer_list<std::size_t> shape) {
  auto* heap = new std::vector<double>(std::move(v));
  nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<double>*>(p); });
  return nb::ndarray<nb::numpy, double>(heap->data(), shape, owner);
}

inline Eigen::Map<const Vector> view(const InVector& v) {
  return {v.data(), static_cast<Eigen::Index>(v.shape(0))};
}

}  // namespace mlcp::python
