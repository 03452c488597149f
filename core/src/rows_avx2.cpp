// The AVX2 variants of RowPgs' sweep and check (mlcp/cpu.hpp): row_sweep.hpp's bodies compiled
// for AVX2 in a file of their own.
#include "mlcp/cpu.hpp"

#if MLCP_CPU_DISPATCH
#include "row_sweep.hpp"

namespace mlcp {

void RowPgs::sweepAvx2(double* xs) { sweepRows<true>(xs); }

Accuracy RowPgs::checkAvx2(const Vector& x, double bNorm) const {
  return checkRows<true>(x, bNorm);
}

}  // namespace mlcp
#endif
