// core/src/projection/row_sweep.hpp (internal): the bodies of RowPgs' sweep and check
// (mlcp/solvers/row_pgs.hpp), always inlined into the functions that run them: row_pgs.cpp's
// baseline sweepOnce and packedAccuracy, and row_pgs_avx2.cpp's AVX2 variants (cpu_dispatch.hpp).
// Each of the two files holds one copy: two copies of the unrolled sweep in one file made GCC stop
// inlining Eigen's 6-vector operations into them (its unit growth limit), which the sweep's speed
// depends on.
#pragma once

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "mlcp/residual.hpp"
#include "mlcp/solvers/row_pgs.hpp"
#include "projection/row_pack.hpp"
#include "projection/row_simd.hpp"

namespace mlcp {

template <bool Wide>
[[gnu::always_inline]] inline Accuracy RowPgs::Packing::checkRows(const Vector& x,
                                                                  double bNorm) const {
  // step_i w_i = (1 - keep) x_i + shift + sA va + sB vb, the sweep's own terms (row_pack.hpp),
  // scaled back by scale_i = 1 / step_i; the bounds with findex applied at x. In blocks of rows
  // that stay in L1 (w in a small buffer, the rows read twice): one loop for both spilled the
  // accumulators to the stack and chained every row through a store and a load (perf).
  constexpr int kBlock = 64;
  const int n = static_cast<int>(packed_.size());
  const double* xs = x.data();
  AccuracyAccumulator a;
  double w[kBlock];
  for (int first = 0; first < n; first += kBlock) {
    const int count = std::min(kBlock, n - first);
    const PackedRow* rows = packed_.data() + first;
    for (int k = 0; k < count; ++k) {
      const PackedRow& p = rows[k];
      const double jv =
          detail::dot12(p.sA.data(), p.sB.data(), detail::load6<Wide>(velocity_[p.a].v.data()),
                        detail::load6<Wide>(velocity_[p.b].v.data()));
      w[k] = scale_[first + k] * ((1 - p.keep) * xs[first + k] + p.shift + jv);
    }
    for (int k = 0; k < count; ++k) {
      const PackedRow& p = rows[k];
      if (!a.add(xs[first + k], w[k], p.lo, p.hi, p.findex, xs)) return a.result(bNorm);
    }
  }
  return a.result(bNorm);
}

[[gnu::always_inline]] inline double RowPgs::Packing::update(const PackedRow& p, double* xs, int i,
                                                             double jv) {
  double lo = p.lo, hi = p.hi;
  if (p.findex >= 0) {
    const double normal = std::abs(xs[p.findex]);
    lo *= normal;
    hi *= normal;
  }
  // The new x is clamp(c - jv, lo, hi) with c = keep x - shift. The change that moves the
  // velocities is clamped on its own, clamp((c - x) - jv, lo - x, hi - x) (the same up to
  // round-off), so that the chain does not wait for the subtraction x_new - x.
  const double xo = xs[i], c = p.keep * xo - p.shift;
  const double dx = std::clamp((c - xo) - jv, lo - xo, hi - xo);
  xs[i] = std::clamp(c - jv, lo, hi);
  return dx;
}

template <bool Wide>
[[gnu::always_inline]] inline void RowPgs::Packing::sweepRows(double* xs) {
  const int n = static_cast<int>(packed_.size());
  auto update = [&](const PackedRow& p, int i, double jv) __attribute__((always_inline)) {
    return Packing::update(p, xs, i, jv);
  };
  const double* coupling = coupling_.data();
  for (int i = 0; i < n;) {
    const PackedRow& first = packed_[i];
    if (first.a == first.b) {
      // A row joining a body to itself: va and vb are the same object.
      Vector6& v = velocity_[first.a].v;
      const double dx =
          update(first, i, (first.sA.cwiseProduct(v) + first.sB.cwiseProduct(v)).sum());
      v += first.mA * dx;
      v += first.mB * dx;
      ++i;
      continue;
    }
    // A run on two bodies: each row's step J v is its product with the velocities at the
    // run's start plus its couplings to the changes of the run's earlier rows, so the chain
    // from one row to the next is a multiply-add instead of the 12-wide dot after a 12-wide
    // velocity update; the velocities take the run's changes at its end. Unrolled per length
    // so that the changes stay in registers (reading them back from a stack array in pairs
    // stalled store forwarding on every coupling).
    const int length = first.run;
    auto sweepRun = [&](auto size) __attribute__((always_inline)) {
      constexpr int L = decltype(size)::value;
      double* const pa = velocity_[first.a].v.data();
      double* const pb = velocity_[first.b].v.data();
      const detail::Six<Wide> va = detail::load6<Wide>(pa), vb = detail::load6<Wide>(pb);
      double dxs[L];
#pragma GCC unroll 8
      for (int k = 0; k < L; ++k) {
        const PackedRow& p = packed_[i + k];
        double jv = detail::dot12(p.sA.data(), p.sB.data(), va, vb);
#pragma GCC unroll 8
        for (int m = 0; m < k; ++m) jv += coupling[m] * dxs[m];
        coupling += k;
        dxs[k] = update(p, i + k, jv);
      }
      detail::Six<Wide> da{}, db{};
#pragma GCC unroll 8
      for (int k = 0; k < L; ++k) {
        da = detail::addScaled(da, packed_[i + k].mA.data(), dxs[k]);
        db = detail::addScaled(db, packed_[i + k].mB.data(), dxs[k]);
      }
      detail::store6(pa, detail::add(va, da));
      detail::store6(pb, detail::add(vb, db));
    };
    static_assert(kMaxRun == 8, "one case per run length");
    switch (length) {
      case 1: sweepRun(std::integral_constant<int, 1>()); break;
      case 2: sweepRun(std::integral_constant<int, 2>()); break;
      case 3: sweepRun(std::integral_constant<int, 3>()); break;
      case 4: sweepRun(std::integral_constant<int, 4>()); break;
      case 5: sweepRun(std::integral_constant<int, 5>()); break;
      case 6: sweepRun(std::integral_constant<int, 6>()); break;
      case 7: sweepRun(std::integral_constant<int, 7>()); break;
      default: sweepRun(std::integral_constant<int, 8>()); break;
    }
    i += length;
  }
}

}  // namespace mlcp
