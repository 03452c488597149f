// Row i of a RowSystem as an engine hands it to RowPgs' engine entry point (RowPgs::Row), with
// its warm start and base: for tests of that entry point against solve(RowSystem).
#pragma once

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

}  // namespace mlcp::test
