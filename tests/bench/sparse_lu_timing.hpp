// The benchmarks' sparse-factorization timings: a matrix in compressed columns, the median of
// repeated runs, and KLU and UMFPACK each analysing, factoring and solving it (one function per
// library, so every benchmark times them the same way).
#pragma once

#include <suitesparse/klu.h>
#include <suitesparse/umfpack.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::bench {

// n x n in compressed sparse columns.
struct Csc {
  int n = 0;
  std::vector<int> start, index;
  std::vector<double> values;
  Vector times(const Vector& z) const {
    Vector out = Vector::Zero(n);
    for (int j = 0; j < n; ++j)
      for (int e = start[j]; e < start[j + 1]; ++e) out[index[e]] += values[e] * z[j];
    return out;
  }
};

// Median wall-clock milliseconds of run(): at least 5 runs, more up to 0.5 s or 200 runs.
inline double medianMs(const std::function<void()>& run) {
  std::vector<double> t;
  double total = 0;
  while (t.size() < 5 || (total < 500 && t.size() < 200)) {
    const auto t0 = std::chrono::steady_clock::now();
    run();
    t.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    total += t.back();
  }
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return t[t.size() / 2];
}

inline double relResidual(const Csc& s, const Vector& r, const Vector& z) {
  return (s.times(z) - r).norm() / r.norm();
}

// A library's factorization of one matrix: median ms and the relative residual of its solve
// (-1 when it failed).
struct Timing {
  double ms = -1, residual = -1;
};

// KLU on s: the numeric factorization alone (analysis once) or, with analyse, analysis and
// factorization together (a pattern seen once).
inline Timing kluTiming(const Csc& s, const Vector& r, bool analyse = false) {
  klu_common c;
  klu_defaults(&c);
  std::vector<int> start = s.start, index = s.index;
  std::vector<double> values = s.values;
  klu_symbolic* sym = klu_analyze(s.n, start.data(), index.data(), &c);
  klu_numeric* num = nullptr;
  Timing t;
  t.ms = medianMs([&] {
    if (num) klu_free_numeric(&num, &c);
    if (analyse) {
      klu_free_symbolic(&sym, &c);
      sym = klu_analyze(s.n, start.data(), index.data(), &c);
    }
    num = sym ? klu_factor(start.data(), index.data(), values.data(), sym, &c) : nullptr;
  });
  Vector z = r;
  if (num && klu_solve(sym, num, s.n, 1, z.data(), &c)) t.residual = relResidual(s, r, z);
  if (num) klu_free_numeric(&num, &c);
  klu_free_symbolic(&sym, &c);
  return t;
}

// UMFPACK on s, with the same two modes.
inline Timing umfpackTiming(const Csc& s, const Vector& r, bool analyse = false) {
  void* sym = nullptr;
  void* num = nullptr;
  auto symbolic = [&] {
    umfpack_di_symbolic(s.n, s.n, s.start.data(), s.index.data(), s.values.data(), &sym, nullptr,
                        nullptr);
  };
  symbolic();
  Timing t;
  t.ms = medianMs([&] {
    if (num) umfpack_di_free_numeric(&num);
    if (analyse) {
      umfpack_di_free_symbolic(&sym);
      symbolic();
    }
    umfpack_di_numeric(s.start.data(), s.index.data(), s.values.data(), sym, &num, nullptr,
                       nullptr);
  });
  Vector z(s.n);
  if (num && umfpack_di_solve(UMFPACK_A, s.start.data(), s.index.data(), s.values.data(), z.data(),
                              r.data(), num, nullptr, nullptr) == UMFPACK_OK)
    t.residual = relResidual(s, r, z);
  if (num) umfpack_di_free_numeric(&num);
  umfpack_di_free_symbolic(&sym);
  return t;
}

}  // namespace mlcp::bench
