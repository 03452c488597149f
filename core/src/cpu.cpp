#include "mlcp/cpu.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "projection/cpu_dispatch.hpp"

namespace mlcp {

namespace detail {

std::atomic<int> cpuPathState{-1};

namespace {

bool cpuHasAvx2() {
#if MLCP_CPU_DISPATCH
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("bmi") &&
         __builtin_cpu_supports("bmi2");
#else
  return false;
#endif
}

}  // namespace

int decideCpuPath() {
  // MLCP_CPU_PATH: "baseline", or "auto" / "avx2" / unset for the best the CPU has.
  const char* env = std::getenv("MLCP_CPU_PATH");
  const bool baseline = env && std::strcmp(env, "baseline") == 0;
  if (env && !baseline && *env && std::strcmp(env, "auto") != 0 && std::strcmp(env, "avx2") != 0)
    std::fprintf(stderr, "mlcp: MLCP_CPU_PATH=%s is not baseline, avx2 or auto; using auto\n", env);
  const int s = !baseline && cpuHasAvx2() ? 1 : 0;
  int expected = -1;
  // A concurrent first use decides the same; setCpuPath's choice wins over the default.
  cpuPathState.compare_exchange_strong(expected, s, std::memory_order_relaxed);
  return cpuPathState.load(std::memory_order_relaxed);
}

}  // namespace detail

const char* toString(CpuPath path) {
  switch (path) {
    case CpuPath::Baseline: return "baseline";
    case CpuPath::Avx2: return "avx2";
  }
  return "unknown";
}

CpuPath cpuPath() { return detail::avx2Active() ? CpuPath::Avx2 : CpuPath::Baseline; }

bool cpuPathAvailable(CpuPath path) { return path == CpuPath::Baseline || detail::cpuHasAvx2(); }

bool setCpuPath(CpuPath path) {
  if (!cpuPathAvailable(path)) return false;
  detail::cpuPathState.store(path == CpuPath::Avx2 ? 1 : 0, std::memory_order_relaxed);
  return true;
}

}  // namespace mlcp
