#include "island_forms.hpp"

#include <cmath>
#include <vector>

namespace mlcp::bench {

namespace {

bool isFrictionRow(const Problem& p, int i) { return !p.findex.empty() && p.findex[i] >= 0; }

// The rows `keep` of A (symmetric selection), in sparse storage.
SparseMatrix principalSubmatrix(const Problem& p, const std::vector<int>& keep) {
  std::vector<int> position(p.size(), -1);
  for (int k = 0; k < static_cast<int>(keep.size()); ++k) position[keep[k]] = k;
  const SparseMatrix A = p.toSparse();
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < static_cast<int>(keep.size()); ++k)
    for (SparseMatrix::InnerIterator it(A, keep[k]); it; ++it)
      if (position[it.col()] >= 0) t.emplace_back(k, position[it.col()], it.value());
  SparseMatrix S(keep.size(), keep.size());
  S.setFromTriplets(t.begin(), t.end());
  return S;
}

}  // namespace

std::optional<Problem> frictionlessLcp(const Problem& island, std::string* why) {
  std::vector<int> keep;
  int other = 0;
  for (int i = 0; i < island.size(); ++i) {
    if (isFrictionRow(island, i)) continue;
    if (island.lo[i] != 0 || island.hi[i] < kLargeBound) {
      ++other;
      continue;
    }
    keep.push_back(i);
  }
  if (other > 0 || keep.empty()) {
    if (why)
      *why = keep.empty() ? "no contact rows"
                          : std::to_string(other) + " rows are neither contact nor friction rows";
    return std::nullopt;
  }
  Vector b(keep.size());
  for (int k = 0; k < static_cast<int>(keep.size()); ++k) b[k] = island.b[keep[k]];
  return Problem(principalSubmatrix(island, keep), b);
}

Problem fixedBoundBox(const Problem& island, const Vector& reference) {
  Problem box = island;
  for (int i = 0; i < island.size(); ++i) {
    if (!isFrictionRow(island, i)) continue;
    const double normal = std::abs(reference[island.findex[i]]);
    box.lo[i] = island.lo[i] * normal;
    box.hi[i] = island.hi[i] * normal;
  }
  box.findex.clear();
  return box;
}

Problem cappedBox(const Problem& box, double cap) {
  Problem capped = box;
  for (int i = 0; i < box.size(); ++i) {
    if (!std::isfinite(capped.lo[i]) || capped.lo[i] < -cap) capped.lo[i] = -cap;
    if (!std::isfinite(capped.hi[i]) || capped.hi[i] > cap) capped.hi[i] = cap;
  }
  return capped;
}

}  // namespace mlcp::bench
