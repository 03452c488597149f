#include "linalg/ordering.hpp"

#include <suitesparse/cholmod.h>

namespace mlcp::linalg {

std::vector<int> fillReducingOrder(int n, const std::vector<int>& start,
                                   const std::vector<int>& index) {
  std::vector<int> order;
  if (n <= 0 || static_cast<int>(start.size()) != n + 1) return order;
  cholmod_common common;
  cholmod_start(&common);
  common.print = 0;
  common.error_handler = nullptr;
  common.nmethods = 2;
  common.method[0].ordering = CHOLMOD_AMD;
  common.method[1].ordering = CHOLMOD_NESDIS;
  common.postorder = 1;
  // A pattern-only header over the caller's arrays (cholmod_analyze reads the pattern alone).
  cholmod_sparse graph{};
  graph.nrow = graph.ncol = static_cast<size_t>(n);
  graph.nzmax = index.size();
  graph.p = const_cast<int*>(start.data());
  graph.i = const_cast<int*>(index.data());
  graph.stype = 1;
  graph.itype = CHOLMOD_INT;
  graph.xtype = CHOLMOD_PATTERN;
  graph.dtype = CHOLMOD_DOUBLE;
  graph.sorted = 1;
  graph.packed = 1;
  cholmod_factor* factor = cholmod_analyze(&graph, &common);
  if (factor && common.status == CHOLMOD_OK) {
    const int* perm = static_cast<const int*>(factor->Perm);
    order.assign(perm, perm + n);
  }
  if (factor) cholmod_free_factor(&factor, &common);
  cholmod_finish(&common);
  return order;
}

}  // namespace mlcp::linalg
