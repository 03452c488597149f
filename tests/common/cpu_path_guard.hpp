// Restores the process's CPU path (mlcp/cpu.hpp) when a test that switches it ends, however it
// ends.
#pragma once

#include "mlcp/cpu.hpp"

namespace mlcp::test {

class CpuPathGuard {
 public:
  CpuPathGuard() : saved_(cpuPath()) {}
  ~CpuPathGuard() { setCpuPath(saved_); }
  CpuPathGuard(const CpuPathGuard&) = delete;
  CpuPathGuard& operator=(const CpuPathGuard&) = delete;

 private:
  CpuPath saved_;
};

}  // namespace mlcp::test
