#include "linalg/block_update.hpp"

#include "projection/cpu_dispatch.hpp"
#include "projection/row_simd.hpp"

namespace mlcp::detail {

namespace {

// c -= l u on column-major 6 x 6 blocks (block_update.hpp has the order of operations).
template <bool Wide>
[[gnu::always_inline]] inline void subtractProduct(double* c, const double* l, const double* u) {
  const Six<Wide> l0 = load6<Wide>(l), l1 = load6<Wide>(l + 6), l2 = load6<Wide>(l + 12);
  const Six<Wide> l3 = load6<Wide>(l + 18), l4 = load6<Wide>(l + 24), l5 = load6<Wide>(l + 30);
  for (int j = 0; j < 6; ++j) {
    const double* uj = u + 6 * j;
    Six<Wide> cj = load6<Wide>(c + 6 * j);
    cj = subScaled(cj, l0, uj[0]);
    cj = subScaled(cj, l1, uj[1]);
    cj = subScaled(cj, l2, uj[2]);
    cj = subScaled(cj, l3, uj[3]);
    cj = subScaled(cj, l4, uj[4]);
    cj = subScaled(cj, l5, uj[5]);
    store6(c + 6 * j, cj);
  }
}

template <bool Wide>
[[gnu::always_inline]] inline void subtractAll(Block6* blocks, int first, int count,
                                               const int* update) {
  for (int a = 0; a < count; ++a) {
    const double* l = blocks[first + 2 * a].data();
    for (int b = 0; b < count; ++b)
      subtractProduct<Wide>(blocks[*update++].data(), l, blocks[first + 2 * b + 1].data());
  }
}

#if MLCP_CPU_DISPATCH
MLCP_AVX2_VARIANT void subtractAllAvx2(Block6* blocks, int first, int count, const int* update) {
  subtractAll<true>(blocks, first, count, update);
}
#endif

}  // namespace

void subtractPivotProducts(Block6* blocks, int first, int count, const int* update) {
#if MLCP_CPU_DISPATCH
  if (avx2Active()) return subtractAllAvx2(blocks, first, count, update);
#endif
  subtractAll<false>(blocks, first, count, update);
}

}  // namespace mlcp::detail
