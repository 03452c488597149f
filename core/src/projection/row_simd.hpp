// core/src/projection/row_simd.hpp (internal): the 6- and 12-wide products of RowPgs' sweeps and
// check in GCC's generic vectors, four entries and two: compiled as pairs of 2-wide SSE2 operations
// for the baseline and as one 4-wide and one 2-wide AVX operation in the AVX2 variants
// (mlcp/cpu.hpp), with the same operations in the same order either way (so the same bits). The
// order is that of Eigen's Vector6 expressions (a 6-vector in 2-wide packets;
// tests/core/cpu_test.cpp compares them on random products), so RowPgs' iterates equal those of the
// Eigen formulation.
#pragma once

#include <cstring>

// D4 values stay inside inlined code (no call passes them), so the ABI note does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace mlcp::detail {

using D2 = double __attribute__((vector_size(16)));
using D4 = double __attribute__((vector_size(32)));

[[gnu::always_inline]] inline D4 load4(const double* p) {
  D4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline D2 load2(const double* p) {
  D2 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void store4(double* p, D4 v) { std::memcpy(p, &v, sizeof v); }
[[gnu::always_inline]] inline void store2(double* p, D2 v) { std::memcpy(p, &v, sizeof v); }

// A 6-vector in registers: entries 0-3 and 4-5 (Wide, for the AVX2 variants), or three pairs
// (the baseline: GCC compiles 4-wide generic vectors without AVX through the stack;
// docs/decisions.md, "RowPgs: packing, sweeps and check"). Every function below does the same
// operations on both.
template <bool Wide>
struct Six;
template <>
struct Six<true> {
  D4 head;
  D2 tail;
};
template <>
struct Six<false> {
  D2 p0, p1, p2;
};

template <bool Wide>
[[gnu::always_inline]] inline Six<Wide> load6(const double* p) {
  if constexpr (Wide)
    return {load4(p), load2(p + 4)};
  else
    return {load2(p), load2(p + 2), load2(p + 4)};
}
template <bool Wide>
[[gnu::always_inline]] inline void store6(double* p, const Six<Wide>& v) {
  if constexpr (Wide) {
    store4(p, v.head);
    store2(p + 4, v.tail);
  } else {
    store2(p, v.p0);
    store2(p + 2, v.p1);
    store2(p + 4, v.p2);
  }
}
// a + s m, entry by entry.
template <bool Wide>
[[gnu::always_inline]] inline Six<Wide> addScaled(const Six<Wide>& a, const double* m, double s) {
  const D2 s2 = {s, s};
  if constexpr (Wide)
    return {a.head + load4(m) * D4{s, s, s, s}, a.tail + load2(m + 4) * s2};
  else
    return {a.p0 + load2(m) * s2, a.p1 + load2(m + 2) * s2, a.p2 + load2(m + 4) * s2};
}
// c - m s, entry by entry (m in registers).
template <bool Wide>
[[gnu::always_inline]] inline Six<Wide> subScaled(const Six<Wide>& c, const Six<Wide>& m,
                                                  double s) {
  const D2 s2 = {s, s};
  if constexpr (Wide)
    return {c.head - m.head * D4{s, s, s, s}, c.tail - m.tail * s2};
  else
    return {c.p0 - m.p0 * s2, c.p1 - m.p1 * s2, c.p2 - m.p2 * s2};
}
template <bool Wide>
[[gnu::always_inline]] inline Six<Wide> add(const Six<Wide>& a, const Six<Wide>& b) {
  if constexpr (Wide)
    return {a.head + b.head, a.tail + b.tail};
  else
    return {a.p0 + b.p0, a.p1 + b.p1, a.p2 + b.p2};
}

// sA . va + sB . vb as Eigen summed (sA.cwiseProduct(va) + sB.cwiseProduct(vb)).sum() for
// 6-vectors: e_j = sA_j va_j + sB_j vb_j, then (e0 + (e2 + e4)) + (e1 + (e3 + e5)).
template <bool Wide>
[[gnu::always_inline]] inline double dot12(const double* sA, const double* sB, const Six<Wide>& va,
                                           const Six<Wide>& vb) {
  D2 s;
  if constexpr (Wide) {
    const D4 e = load4(sA) * va.head + load4(sB) * vb.head;
    const D2 e45 = load2(sA + 4) * va.tail + load2(sB + 4) * vb.tail;
    s = D2{e[0], e[1]} + (D2{e[2], e[3]} + e45);
  } else {
    const D2 e01 = load2(sA) * va.p0 + load2(sB) * vb.p0;
    const D2 e23 = load2(sA + 2) * va.p1 + load2(sB + 2) * vb.p1;
    const D2 e45 = load2(sA + 4) * va.p2 + load2(sB + 4) * vb.p2;
    s = e01 + (e23 + e45);
  }
  return s[0] + s[1];
}

}  // namespace mlcp::detail

#pragma GCC diagnostic pop
