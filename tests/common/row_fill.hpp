// Row i of a RowSystem as an engine hands it to RowPgs' engine entry point (RowPgs::Row), with
// its warm start and base, and a solve through that entry point: for tests of it against
// solve(RowSystem).
#pragma once

#include <gtest/gtest.h>

#include "mlcp/rows.hpp"

namespace mlcp::test {

inline RowPgs::Row rowOf(const RowSystem& s, int i, double start, double base) {
  RowPgs::Row r;
  r.bodyA = s.rows[i].bodyA;
  r.bodyB = s.rows[i].bodyB;
  r.jA = s.rows[i].jA;
  r.jB = s.rows[i].jB;
  r.b = s.b[i];
  r.cfm = s.cfm[i];
  r.lo = s.lo[i];
  r.hi = s.hi[i];
  r.findex = s.findex.empty() ? -1 : s.findex[i];
  r.start = start;
  r.base = base;
  return r;
}

// RowPgs::solve with a row fill over s, each row with start[i] and base[i] (fetched in batches).
inline Result solveFromRows(RowPgs& pgs, const RowSystem& s, const Vector& start,
                            const Vector& base, Vector& x) {
  int calls = 0;
  const Result r = pgs.solve(
      s.bodies, s.size(),
      [&](int first, int count, RowPgs::Row* out) {
        ++calls;
        for (int k = 0; k < count; ++k)
          out[k] = rowOf(s, first + k, start[first + k], base[first + k]);
      },
      x);
  EXPECT_GE(calls, (s.size() + 63) / 64);
  return r;
}

}  // namespace mlcp::test
