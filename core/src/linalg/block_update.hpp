// The inner loop of body space's block LU (linalg/body_space.hpp): for one pivot k, the update
// C_ab -= L_ak U_kb of every pair (a, b) of the bodies below it, on 6 x 6 column-major blocks.
// Internal to the library.
//
// The elimination spends most of its time here: 216 multiply-adds per update, and the updates
// number the sum over pivots of the squared count of blocks below them. Each column j
// of C is one 6-vector (rows/row_simd.hpp's Six) and takes c_j = c_j - L_k u_kj for k = 0..5 in
// that order, L's six columns held in registers across the six columns of U: three 2-wide SSE2
// multiplies and subtractions a term on the baseline, a 4-wide and a 2-wide AVX pair in the AVX2
// variant; the same operations in the same order, so the same bits (mlcp/cpu.hpp,
// tests/core/cpu_test.cpp). The variant is chosen as RowPgs' loops choose theirs.
#pragma once

#include <Eigen/Core>

namespace mlcp::detail {

using Block6 = Eigen::Matrix<double, 6, 6>;

// For a in [0, count): blocks[update[a * count + b]] -= lower[a] * upper[b], b in [0, count);
// lower(a) and upper(b) are the pivot's L and U blocks, at blocks[first + 2 a] and
// blocks[first + 2 b + 1].
void subtractPivotProducts(Block6* blocks, int first, int count, const int* update);

}  // namespace mlcp::detail
