// The AVX2 variants of RowPgs' sweep and check (cpu_dispatch.hpp): row_sweep.hpp's bodies
// compiled for AVX2 in a file of their own.
#include "projection/cpu_dispatch.hpp"

#if MLCP_CPU_DISPATCH
#include "projection/row_sweep.hpp"

namespace mlcp {

void RowPgs::Packing::sweepAvx2(double* xs) { sweepRows<true>(xs); }

Accuracy RowPgs::Packing::checkAvx2(const Vector& x, double bNorm) const {
  return checkRows<true>(x, bNorm);
}

}  // namespace mlcp
#endif
