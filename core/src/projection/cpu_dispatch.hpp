// core/src/projection/cpu_dispatch.hpp (internal): how RowPgs' hot loops pick their machine code
// (mlcp/cpu.hpp says which paths there are and how a program chooses one).
#pragma once

#include <atomic>

#include "mlcp/cpu.hpp"

// For the solvers' sources: MLCP_CPU_DISPATCH is 1 where an AVX2 variant is compiled, and
// MLCP_AVX2_VARIANT marks its functions (noinline: a variant is one function with the shared
// body inlined into it; flatten: everything that body calls is inlined into it too, so the
// variant has the baseline's code shape; without it GCC compiles the engine path's packing
// variant to different code).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(MLCP_NO_CPU_DISPATCH)
#define MLCP_CPU_DISPATCH 1
#define MLCP_AVX2_VARIANT __attribute__((noinline, flatten, target("avx2,bmi,bmi2")))
#else
#define MLCP_CPU_DISPATCH 0
#endif

namespace mlcp::detail {
// 1 = Avx2, 0 = Baseline, -1 = not decided yet.
int decideCpuPath();
extern std::atomic<int> cpuPathState;
// Whether the hot loops take their AVX2 variant (decided at the first call).
inline bool avx2Active() {
  const int s = cpuPathState.load(std::memory_order_relaxed);
  return (s < 0 ? decideCpuPath() : s) == 1;
}
}  // namespace mlcp::detail
