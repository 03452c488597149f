// mlcp/registry.hpp: solvers by name, for the CLI, the adapters and the tests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mlcp/solver.hpp"

namespace mlcp {

struct SolverInfo {
  const char* name;         // "pgs"
  const char* description;  // one line for --help
  std::unique_ptr<Solver> (*make)();
};

// Every registered solver, in a fixed order.
const std::vector<SolverInfo>& solvers();
// A new solver of that name, or nullptr (with a message listing the valid names in *error).
// "a>b>c" makes a verified fallback chain of registered solvers (fallback.hpp).
std::unique_ptr<Solver> makeSolver(const std::string& name, std::string* error = nullptr);
// Whether a single solver of this name is registered (no chain; nothing is made).
bool isRegistered(const std::string& name);
// "gs, pgs, ..." for messages and help texts.
std::string solverNames();
// Adds a solver to the registry (a program's own, or a test's injected one); false when the
// name is taken or holds '>'. Register before solving: lookups and registration are not
// synchronized.
bool registerSolver(const SolverInfo& info);

}  // namespace mlcp
