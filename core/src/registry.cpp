#include "mlcp/registry.hpp"

#include "mlcp/lemke.hpp"
#include "mlcp/pgs.hpp"

namespace mlcp {

namespace {
template <class S>
std::unique_ptr<Solver> make() {
  return std::make_unique<S>();
}
}  // namespace

const std::vector<SolverInfo>& solvers() {
  static const std::vector<SolverInfo> list = {
      {"gs", "Gauss-Seidel for problems without bounds (linear systems)", &make<GaussSeidelSolver>},
      {"pgs", "projected Gauss-Seidel / SOR for boxed problems with findex", &make<PgsSolver>},
      {"lemke", "Lemke's lexicographic complementary pivoting, dense; boxes, findex by fixed point",
       &make<LemkeSolver>},
  };
  return list;
}

std::string solverNames() {
  std::string s;
  for (const SolverInfo& info : solvers()) {
    if (!s.empty()) s += ", ";
    s += info.name;
  }
  return s;
}

std::unique_ptr<Solver> makeSolver(const std::string& name, std::string* error) {
  for (const SolverInfo& info : solvers())
    if (name == info.name) return info.make();
  if (error) *error = "unknown solver '" + name + "' (known: " + solverNames() + ")";
  return nullptr;
}

}  // namespace mlcp
