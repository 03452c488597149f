// Row i of a RowSystem as an engine hands it to RowPgs' engine entry point (a RowPgs::RowSource
// reading the system's rows in place), with its warm start and base, and a solve through that
// entry point: for tests of it against solve(RowSystem).
#pragma once

#include <gtest/gtest.h>

#include "mlcp/rows.hpp"
#include "mlcp/solvers/row_pgs.hpp"

namespace mlcp::test {

class SystemRows final : public RowPgs::RowSource {
 public:
  SystemRows(const RowSystem& s, const Vector& start, const Vector& base)
      : s_(s), start_(start), base_(base) {}
  RowPgs::RowView row(int i) override {
    ++calls;
    RowPgs::RowView r;
    const ConstraintRow& c = s_.rows[i];
    r.bodyA = c.bodyA;
    r.bodyB = c.bodyB;
    r.linA = c.jA.data();
    r.angA = c.jA.data() + 3;
    r.linB = c.jB.data();
    r.angB = c.jB.data() + 3;
    r.b = s_.b[i];
    r.cfm = s_.cfm[i];
    r.lo = s_.lo[i];
    r.hi = s_.hi[i];
    r.findex = s_.findex.empty() ? -1 : s_.findex[i];
    r.start = start_[i];
    r.base = base_[i];
    return r;
  }
  int calls = 0;

 private:
  const RowSystem& s_;
  const Vector& start_;
  const Vector& base_;
};

// RowPgs::solve with a row source over s, each row with start[i] and base[i].
inline Result solveFromRows(RowPgs& pgs, const RowSystem& s, const Vector& start,
                            const Vector& base, Vector& x) {
  SystemRows rows(s, start, base);
  const Result r = pgs.solve(s.bodies, s.size(), rows, x);
  EXPECT_GE(rows.calls, s.size());
  return r;
}

}  // namespace mlcp::test
