// body_space_bench: the factorization of body-space S (linalg/body_space.hpp) on friction
// pyramids, the library's 6x6-block LU against SuiteSparse's CHOLMOD, KLU and UMFPACK on the same
// matrices in one run.
//
//   build/bench/body_space_bench [levels...]      (default 10 20 44: 55, 210 and 990 boxes)
//
// A level count with a trailing s (14s) is a square pyramid (1015 boxes for 14), whose body
// graph is three-dimensional (larger separators, so larger dense blocks in S's factor). Per
// pyramid (tests/common/contact_scenes.hpp BoxPyramid, sliding bodies, cfm 1e-5/dt) the
// clamped and sliding rows are those of newton's answer (tolerance 1e-6, at most 60 steps), S is
// assembled as newton's steps assemble it (rho = 0), and each method factors it: the block LU
// (assembly and elimination, in the library's CHOLMOD order) and, on the S it exports, CHOLMOD
// (analysis once, then supernodal or simplicial as CHOLMOD decides), KLU and UMFPACK (analysis
// once). S with its sliding rows is not symmetric, so CHOLMOD is timed on the S of the same
// clamped rows without them (what a Cholesky step plus a correction for the sliding rows would
// factor); the block LU is timed on both. Each time is the median of repeats (at least 5, until
// 0.5 s); each factor is checked by a solve (relative residual of S z = r). The BLAS is whichever
// libblas.so.3 the process loaded (printed).
//
// A second table does the same for the row-space systems of newton's pivoting phase
// (core/src/newton/block_pivoting.hpp) when body space does not apply (cfm = 0 at rho = 0): K =
// A_CC with each sliding row's column c_t A_{C,t} added to its normal's column, in the AMD order of
// A that block pivoting inherits, factored by the library's SymmetricPatternLu (LU without pivoting
// on the symmetric pattern; LDL^T without the sliding rows) against CHOLMOD (without the sliding
// rows), KLU and UMFPACK on the same matrix.
#include <suitesparse/cholmod.h>

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "bench/sparse_lu_timing.hpp"
#include "common/contact_scenes.hpp"
#include "linalg/body_space.hpp"            // BodySpaceSystem (internal)
#include "linalg/symmetric_pattern_lu.hpp"  // (internal)
#include "mlcp/solvers/newton.hpp"

namespace {

using mlcp::Vector;
using mlcp::bench::Csc;
using mlcp::bench::medianMs;
using mlcp::bench::relResidual;
using mlcp::bench::Timing;

std::string loadedBlas() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line))
    if (line.find("libblas") != std::string::npos || line.find("libopenblas") != std::string::npos)
      return line.substr(line.find('/'));
  return "none";
}

Timing cholmod(const Csc& s, const Vector& r) {
  cholmod_common c;
  cholmod_start(&c);
  c.print = 0;
  cholmod_sparse a{};
  a.nrow = a.ncol = s.n;
  a.nzmax = s.index.size();
  a.p = const_cast<int*>(s.start.data());
  a.i = const_cast<int*>(s.index.data());
  a.x = const_cast<double*>(s.values.data());
  a.stype = 1;
  a.itype = CHOLMOD_INT;
  a.xtype = CHOLMOD_REAL;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = a.packed = 1;
  cholmod_factor* l = cholmod_analyze(&a, &c);
  Timing t;
  bool ok = true;
  t.ms = medianMs([&] { ok = cholmod_factorize(&a, l, &c) && c.status == CHOLMOD_OK && ok; });
  cholmod_dense b{};
  b.nrow = b.nzmax = b.d = s.n;
  b.ncol = 1;
  Vector rhs = r;
  b.x = rhs.data();
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = ok ? cholmod_solve(CHOLMOD_A, l, &b, &c) : nullptr;
  if (x) {
    t.residual = relResidual(s, r, Eigen::Map<Vector>(static_cast<double*>(x->x), s.n));
    cholmod_free_dense(&x, &c);
  }
  cholmod_free_factor(&l, &c);
  cholmod_finish(&c);
  return t;
}

// The clamped rows of x (strictly inside their effective bounds) and the sliding friction rows
// (at a bound, their normal clamped) with x_t = c_t x_n.
struct Sets {
  std::vector<int> order, pos, sliding;
  std::vector<double> coeff;
};

Sets setsOf(const mlcp::Problem& p, const Vector& x) {
  Sets s;
  const int n = p.size();
  s.pos.assign(n, -1);
  for (int i = 0; i < n; ++i) {
    const double lo = p.effectiveLo(i, x), hi = p.effectiveHi(i, x);
    if (x[i] > lo && x[i] < hi) {
      s.pos[i] = static_cast<int>(s.order.size());
      s.order.push_back(i);
    }
  }
  for (int t = 0; t < n; ++t) {
    const int f = p.findex.empty() ? -1 : p.findex[t];
    if (f < 0 || s.pos[t] >= 0 || s.pos[f] < 0 || x[f] <= 0) continue;
    s.sliding.push_back(t);
    s.coeff.push_back(x[t] / x[f]);
  }
  return s;
}

// A timing as a table cell: "median ms (solve check)", "-" when not run.
std::string cell(const Timing& t) {
  char buf[64];
  if (t.ms < 0) return std::string("-");
  std::snprintf(buf, sizeof buf, "%.3g ms (%.0e)", t.ms, t.residual);
  return std::string(buf);
}

void row(int boxes, int coords, const Sets& sets, bool withSliding, const Csc& s, double blockMs,
         double blockResidual, const Vector& r) {
  const Timing ch = withSliding ? Timing{} : cholmod(s, r);
  const Timing k = mlcp::bench::kluTiming(s, r), u = mlcp::bench::umfpackTiming(s, r);
  std::printf("| %d | %d | %zu | %zu | %s | %zu | %.3g ms (%.0e) | %s | %s | %s |\n", boxes, coords,
              sets.order.size(), withSliding ? sets.sliding.size() : 0,
              withSliding ? "with sliding rows" : "without", s.index.size(), blockMs, blockResidual,
              cell(ch).c_str(), cell(k).c_str(), cell(u).c_str());
}

// The bench's pyramid: levels boxes at the bottom (square: a square pyramid), sliding bodies.
mlcp::test::PyramidSpec pyramidSpec(int levels, bool square) {
  mlcp::test::PyramidSpec spec;
  spec.levels = levels;
  spec.square = square;
  spec.sideVelocity = 0.5;
  return spec;
}

// The sets of newton's answer (tolerance 1e-6, at most 60 steps) on the pyramid's problem p.
Sets answerSets(const mlcp::test::BoxPyramid& pyramid, const mlcp::Problem& p) {
  mlcp::NewtonSolver newton;
  newton.options().tolerance = 1e-6;
  newton.options().maxIterations = 60;
  newton.useRows(&pyramid.rows());
  Vector x;
  newton.solve(p, x);
  return setsOf(p, x);
}

void bench(int levels, bool square) {
  mlcp::test::BoxPyramid pyramid(pyramidSpec(levels, square));
  const mlcp::RowSystem& rows = pyramid.rows();
  const mlcp::Problem p = rows.assemble(true);
  const Sets sets = answerSets(pyramid, p);
  double dMax = 0;
  for (int i = 0; i < p.size(); ++i) dMax = std::max(dMax, p.diagonal(i));
  mlcp::detail::BodySpaceSystem body;
  if (!body.prepareFor(rows, p, dMax)) {
    std::printf("| %d | - | body space does not apply |\n", pyramid.boxes());
    return;
  }
  const double minDiagonal = mlcp::kBodyMinDiagonal * dMax;
  for (const bool withSliding : {true, false}) {
    const std::vector<int> sliding = withSliding ? sets.sliding : std::vector<int>{};
    const std::vector<double> coeff = withSliding ? sets.coeff : std::vector<double>{};
    Csc s;
    s.n = body.size();
    body.assemble(sets.order, sets.pos, sliding, coeff, p.findex, 0, minDiagonal);
    body.assembled(s.start, s.index, s.values);
    const double blockMs = medianMs(
        [&] { body.factor(sets.order, sets.pos, sliding, coeff, p.findex, 0, minDiagonal); });
    // The block LU solves K y = r on the clamped rows; its S solve is checked through K: S z = r
    // is what the other methods solve, so the block LU's residual is of K y = r.
    Vector r = Vector::Ones(s.n);
    Vector y = Vector::Ones(static_cast<int>(sets.order.size())), ky;
    const Vector y0 = y;
    body.solve(y);
    // K y = D y + J_C W G_C^T y: through the rows (multiply is A = J W J^T + cfm on all rows).
    Vector full = Vector::Zero(p.size());
    for (size_t c = 0; c < sets.order.size(); ++c) full[sets.order[c]] = y[c];
    for (size_t k = 0; k < sliding.size(); ++k)
      full[sliding[k]] = coeff[k] * full[p.findex[sliding[k]]];
    body.multiply(full, sets.order, ky);
    const double blockResidual = (ky - y0).norm() / y0.norm();
    row(pyramid.boxes(), s.n, sets, withSliding, s, blockMs, blockResidual, r);
  }
}

// K of the sets (with or without the sliding rows' coupling) on A_CC's pattern, the clamped rows
// in the AMD order of A; kt holds K^T's values on the same entries. False when a sliding row's
// coupling falls outside that pattern (block pivoting then factors K by a general LU).
bool clampedSystem(const mlcp::Problem& p, const Sets& sets, bool withSliding, Csc& k,
                   std::vector<double>& kt) {
  const mlcp::SparseMatrix& a = p.sparseA();  // symmetric: row i is column i
  const Eigen::SparseMatrix<double, Eigen::ColMajor, int> pattern = a;
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
  Eigen::AMDOrdering<int>()(pattern, perm);
  std::vector<int> pos(p.size(), -1), order;
  for (int r = 0; r < p.size(); ++r) {
    const int i = perm.indices()[r];
    if (sets.pos[i] >= 0) {
      pos[i] = static_cast<int>(order.size());
      order.push_back(i);
    }
  }
  const int m = static_cast<int>(order.size());
  // Dense per column is too big at 990 boxes: K's columns as maps from rows to values.
  std::vector<std::vector<std::pair<int, double>>> col(m);
  for (int c = 0; c < m; ++c)
    for (mlcp::SparseMatrix::InnerIterator it(a, order[c]); it; ++it)
      if (pos[it.index()] >= 0) col[c].push_back({pos[it.index()], it.value()});
  auto add = [&](int c, int r, double v) {
    for (auto& e : col[c])
      if (e.first == r) return (e.second += v), true;
    return false;
  };
  for (size_t q = 0; withSliding && q < sets.sliding.size(); ++q) {
    const int t = sets.sliding[q], c = pos[p.findex[t]];
    for (mlcp::SparseMatrix::InnerIterator it(a, t); it; ++it)
      if (pos[it.index()] >= 0 && !add(c, pos[it.index()], sets.coeff[q] * it.value()))
        return false;
  }
  k.n = m;
  k.start.assign(1, 0);
  k.index.clear();
  k.values.clear();
  for (int c = 0; c < m; ++c) {
    std::sort(col[c].begin(), col[c].end());
    for (const auto& [r, v] : col[c]) {
      k.index.push_back(r);
      k.values.push_back(v);
    }
    k.start.push_back(static_cast<int>(k.index.size()));
  }
  kt.resize(k.values.size());
  for (int c = 0; c < m; ++c)
    for (int e = k.start[c]; e < k.start[c + 1]; ++e) {
      const int r = k.index[e];
      const int* at = std::lower_bound(&k.index[k.start[r]], &k.index[k.start[r + 1]], c);
      kt[e] = k.values[at - k.index.data()];  // K(c, r): the mirror entry (symmetric pattern)
    }
  return true;
}

void pivotingRow(int boxes, const mlcp::Problem& p, const Sets& sets, bool withSliding) {
  Csc k;
  std::vector<double> kt;
  if (!clampedSystem(p, sets, withSliding, k, kt)) {
    std::printf("| %d | %zu | %zu | coupling outside A_CC's pattern |\n", boxes, sets.order.size(),
                sets.sliding.size());
    return;
  }
  const Vector r = Vector::Ones(k.n);
  mlcp::detail::SymmetricPatternLu lu;
  bool ok = true;
  const double ms = medianMs([&] {
    ok = withSliding ? lu.factor(k.n, k.start, k.index, k.values, kt, 0.0)
                     : lu.factorSymmetric(k.n, k.start, k.index, k.values, 0.0);
  });
  Vector z = r;
  if (ok) lu.solve(z);
  const Timing ch = withSliding ? Timing{} : cholmod(k, r);
  const Timing kl = mlcp::bench::kluTiming(k, r), u = mlcp::bench::umfpackTiming(k, r);
  std::printf("| %d | %d | %zu | %zu | %s | %.3g ms (%.0e) | %s | %s | %s |\n", boxes, k.n,
              withSliding ? sets.sliding.size() : 0, k.index.size(),
              withSliding ? "with sliding rows" : "without", ms, ok ? relResidual(k, r, z) : -1.0,
              cell(ch).c_str(), cell(kl).c_str(), cell(u).c_str());
}

void pivotingBench(int levels, bool square) {
  mlcp::test::BoxPyramid pyramid(pyramidSpec(levels, square));
  const mlcp::Problem p = pyramid.rows().assemble(true);
  const Sets sets = answerSets(pyramid, p);
  for (const bool withSliding : {true, false}) pivotingRow(pyramid.boxes(), p, sets, withSliding);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> levels(argv + 1, argv + argc);
  if (levels.empty()) levels = {"10", "20", "44"};
  std::printf("BLAS: %s\n\n", loadedBlas().c_str());
  std::printf(
      "| boxes | S size | clamped rows | sliding rows | S | nnz(S) | block LU | CHOLMOD | KLU | "
      "UMFPACK |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& l : levels) bench(std::atoi(l.c_str()), l.back() == 's');
  std::printf(
      "\nThe pivoting phase's K in row space:\n\n| boxes | clamped rows | sliding rows | nnz(K) | "
      "K | SymmetricPatternLu | CHOLMOD | KLU | UMFPACK "
      "|\n|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& l : levels) pivotingBench(std::atoi(l.c_str()), l.back() == 's');
  return 0;
}
