// KLU against UMFPACK on lemke's basis matrices, in one run: what the factored-basis Lemke
// (core/src/pivoting/lemke_revised.cpp) factors at each refactorization. For each problem file
// (a standard LCP w = M z + q, e.g. an island captured by `mlcp run --capture`), lemke solves it,
// and the bases are [I, -M] restricted to the answer's complementary columns (z_i > 0 takes
// -M_i, else e_i) and to the first 25%, 50% and 75% of those M columns (the bases a pivot
// sequence passes through as z enters). Each basis is analysed and factored anew, as lemke does
// when its basis changes; the table gives the median ms of each library and its solve's
// residual.
//
//   basis_lu_bench FILE...
#include <cstdio>
#include <string>
#include <vector>

#include "bench/sparse_lu_timing.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"

namespace {

using namespace mlcp;

// B = [e_i or -M_i]: -M's column for the rows in mColumns, the unit column otherwise.
bench::Csc basisOf(const SparseMatrix& M, const std::vector<int>& mColumns) {
  const int n = static_cast<int>(M.rows());
  std::vector<bool> fromM(n, false);
  for (int i : mColumns) fromM[i] = true;
  const Eigen::SparseMatrix<double> Mc = M;  // column-major: M's columns contiguous
  bench::Csc b;
  b.n = n;
  b.start.push_back(0);
  for (int j = 0; j < n; ++j) {
    if (fromM[j]) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(Mc, j); it; ++it) {
        b.index.push_back(static_cast<int>(it.row()));
        b.values.push_back(-it.value());
      }
    } else {
      b.index.push_back(j);
      b.values.push_back(1.0);
    }
    b.start.push_back(static_cast<int>(b.index.size()));
  }
  return b;
}

void benchFile(const std::string& path) {
  const Problem p = io::readProblem(path);
  if (p.classify() != ProblemClass::StandardLcp) {
    std::printf("%s: not a standard LCP, skipped\n", path.c_str());
    return;
  }
  auto lemke = makeSolver("lemke");
  Vector z;
  const Result r = lemke->solve(p, z);
  std::vector<int> active;
  for (int i = 0; i < p.size(); ++i)
    if (z[i] > 0) active.push_back(i);
  std::printf("%s: n = %d, lemke %s, %d pivots, %zu basic z\n", path.c_str(), p.size(),
              toString(r.status), r.iterations, active.size());
  const SparseMatrix M = p.toSparse();
  const Vector rhs = Vector::Ones(p.size());
  for (const double share : {0.25, 0.5, 0.75, 1.0}) {
    const std::vector<int> cols(active.begin(),
                                active.begin() + std::size_t(share * active.size()));
    const bench::Csc b = basisOf(M, cols);
    const bench::Timing k = bench::kluTiming(b, rhs, true), u = bench::umfpackTiming(b, rhs, true);
    auto cell = [](const bench::Timing& x) {
      char text[48];
      if (x.residual < 0)
        std::snprintf(text, sizeof text, "%9.3f ms (singular)", x.ms);
      else
        std::snprintf(text, sizeof text, "%9.3f ms (res %.1e)", x.ms, x.residual);
      return std::string(text);
    };
    std::printf("  %4.0f%% of z  nnz %8zu  KLU %s  UMFPACK %s  UMFPACK/KLU %.2f\n", 100 * share,
                b.values.size(), cell(k).c_str(), cell(u).c_str(), u.ms / k.ms);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: basis_lu_bench FILE...\n");
    return 2;
  }
  try {
    for (int a = 1; a < argc; ++a) benchFile(argv[a]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "basis_lu_bench: %s\n", e.what());
    return 2;
  }
  return 0;
}
