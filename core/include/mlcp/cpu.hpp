// mlcp/cpu.hpp: which machine code the hot loops run.
//
// RowPgs (rows.hpp) spends a fixed-sweep solve in three loops: the packing of the engine's rows,
// the sweeps and the residual check; newton on a large island spends most of its steps in one
// loop, the block updates of its body-space factorization (core/src/linalg/block_update.hpp).
// On x86-64 with GCC each of them is compiled twice, for the
// baseline x86-64 (SSE2, what a distribution's packages target) and with AVX2, and the AVX2 code
// runs where the CPU has it. Both are the same source: the same operations in the same order,
// and no fused multiply-adds (the AVX2 variant does not enable FMA, and every target of this
// project is compiled with -ffp-contract=off, so no a * b + c is fused anywhere), so
// they give the same answers bit for bit (tests/core/cpu_test.cpp, and a Bullet pyramid stepped
// under both in tests/bullet/plumbing_test.cpp); only the time differs. The AVX2 code uses the
// VEX encodings throughout and 4-wide vectors for the sweep's and the check's 12-wide row
// products and velocity updates (core/src/projection/row_simd.hpp), and for the 6 x 6 block
// products of the factorization. AVX2 is chosen for these loops alone because they are where
// fixed-sweep pgs and newton's large steps spend their time; building the whole library for
// x86-64-v3 gains about what this dispatch gains (docs/decisions.md). docs/benchmarks.md has
// the times of both paths (bullet_bench --pgs-vs-si, MLCP_CPU_PATH=baseline).
//
// The choice is made once, at first use: AVX2 when the CPU has AVX2, BMI1 and BMI2, unless
// the environment variable MLCP_CPU_PATH is "baseline" ("auto" and "avx2" mean the default; any
// other value is named on stderr and ignored). setCpuPath() changes it for the whole process (for
// comparisons; the solvers read it once per loop, so change it between solves). Builds without
// the dispatch (another compiler or architecture, or CMake's -DMLCP_CPU_DISPATCH=OFF, which
// defines MLCP_NO_CPU_DISPATCH) always run the baseline. The variants and the choice between
// them are internal (core/src/projection/cpu_dispatch.hpp).
#pragma once

namespace mlcp {

enum class CpuPath {
  Baseline,  // the code as compiled for the build's own target
  Avx2,      // the same code compiled with AVX2 (x86-64 with GCC only)
};

const char* toString(CpuPath path);
// The path the hot loops take now.
CpuPath cpuPath();
// Whether this build and this CPU can run the path (Baseline: always).
bool cpuPathAvailable(CpuPath path);
// Switches the hot loops to `path`; false, and no change, when it is not available.
bool setCpuPath(CpuPath path);

}  // namespace mlcp
