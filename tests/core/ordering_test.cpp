// linalg/ordering.hpp: CHOLMOD's fill-reducing order of a symmetric graph.
#include "linalg/ordering.hpp"  // fillReducingOrder (internal)

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

namespace mlcp {
namespace {

struct Graph {
  int n = 0;
  std::vector<int> start, index;  // sorted adjacency, with the diagonal
};

// A w x h grid with 8-neighbour links (a stack of boxes in contact is this kind of graph).
Graph grid(int w, int h) {
  Graph g;
  g.n = w * h;
  g.start.push_back(0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx >= 0 && nx < w && ny >= 0 && ny < h) g.index.push_back(ny * w + nx);
        }
      std::sort(g.index.begin() + g.start.back(), g.index.end());
      g.start.push_back(static_cast<int>(g.index.size()));
    }
  return g;
}

// Entries below the diagonal of the Cholesky factor when eliminating in `order` (each eliminated
// node joins its later neighbours into a clique).
long factorEntries(const Graph& g, const std::vector<int>& order) {
  std::vector<int> rank(g.n);
  for (int r = 0; r < g.n; ++r) rank[order[r]] = r;
  std::vector<std::set<int>> later(g.n);
  for (int k = 0; k < g.n; ++k)
    for (int e = g.start[k]; e < g.start[k + 1]; ++e)
      if (rank[g.index[e]] > rank[k]) later[rank[k]].insert(rank[g.index[e]]);
  long entries = 0;
  for (int r = 0; r < g.n; ++r) {
    entries += static_cast<long>(later[r].size());
    if (later[r].empty()) continue;
    const int parent = *later[r].begin();
    for (int q : later[r])
      if (q != parent) later[parent].insert(q);
  }
  return entries;
}

TEST(Ordering, IsAPermutationWithLessFillThanTheNaturalOrder) {
  const Graph g = grid(50, 50);
  const std::vector<int> order = linalg::fillReducingOrder(g.n, g.start, g.index);
  ASSERT_EQ(static_cast<int>(order.size()), g.n);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < g.n; ++k) ASSERT_EQ(sorted[k], k);
  std::vector<int> natural(g.n);
  for (int k = 0; k < g.n; ++k) natural[k] = k;
  // The natural (banded) order fills about n x bandwidth; AMD or nested dissection less.
  EXPECT_LT(factorEntries(g, order), 0.6 * factorEntries(g, natural));
}

TEST(Ordering, RefusedGraphGivesNoOrder) {
  const Graph g = grid(3, 3);
  EXPECT_TRUE(linalg::fillReducingOrder(0, {0}, {}).empty());
  EXPECT_TRUE(linalg::fillReducingOrder(g.n, {0, 1}, g.index).empty());  // start too short
}

}  // namespace
}  // namespace mlcp
