// A fill-reducing elimination order of a sparse symmetric graph, from SuiteSparse's CHOLMOD
// analysis. Internal to the library.
//
// The graph is given by its adjacency in compressed form (node k's neighbours in
// index[start[k] .. start[k + 1]), sorted; the diagonal may be present). CHOLMOD orders it twice,
// by AMD and by its nested dissection (METIS partitions, constrained AMD inside them), and keeps
// the order whose Cholesky factor has fewer entries. Why both: on the body graph of a 210-box
// pyramid the two are within 5% of each other, while on a 1000-box pyramid nested dissection
// leaves about 0.6x of AMD's fill in the block LU of linalg/body_space.hpp (docs/benchmarks.md,
// "Body space: the factorization of S"). Cost: AMD O(edges), nested dissection a few times
// that (docs/benchmarks.md, "Body space: S against the rows' LU, and the cost of the ordering").
#pragma once

#include <vector>

namespace mlcp::linalg {

// order[r] is the node eliminated at rank r. Empty when CHOLMOD refuses the graph (the caller
// then keeps its own order).
std::vector<int> fillReducingOrder(int n, const std::vector<int>& start,
                                   const std::vector<int>& index);

}  // namespace mlcp::linalg
