#include "mlcp/registry.hpp"

#include "mlcp/island/fallback.hpp"
#include "mlcp/solvers/dantzig.hpp"
#include "mlcp/solvers/ldlt.hpp"
#include "mlcp/solvers/lemke.hpp"
#include "mlcp/solvers/newton.hpp"
#include "mlcp/solvers/pgs.hpp"
#include "mlcp/solvers/proximal.hpp"

namespace mlcp {

namespace {
template <class S>
std::unique_ptr<Solver> make() {
  return std::make_unique<S>();
}

std::vector<SolverInfo>& registered() {
  static std::vector<SolverInfo> list = {
      {"gs", "Gauss-Seidel for problems without bounds (linear systems)", &make<GaussSeidelSolver>},
      {"pgs", "projected Gauss-Seidel / SOR for boxed problems with findex", &make<PgsSolver>},
      {"dantzig", "Dantzig principal pivoting for boxed problems with findex (ODE-style)",
       &make<DantzigSolver>},
      {"newton",
       "semismooth Newton on the natural map (exact findex Jacobian), LU-factored: warm large "
       "islands, small nonsymmetric MLCPs",
       &make<NewtonSolver>},
      {"lemke",
       "Lemke's lexicographic complementary pivoting (dense tableau, or a factored basis above "
       "50 rows); boxes, findex by fixed point",
       &make<LemkeSolver>},
      {"proximal",
       "proximal point on the impulses: newton on A + alpha I from the last iterate, alpha falling "
       "with the residual; exact where A is singular (piles without CFM)",
       &make<ProximalSolver>},
      {"ldlt", "sparse LDL^T (or LU) direct solve for problems without bounds; pattern reused",
       &make<LdltSolver>},
      {"auto", "picks a chain per problem class and size, with verified fallback",
       &make<AutoSolver>},
  };
  return list;
}
}  // namespace

const std::vector<SolverInfo>& solvers() { return registered(); }

bool registerSolver(const SolverInfo& info) {
  const std::string name = info.name ? info.name : "";
  if (name.empty() || name.find('>') != std::string::npos || !info.make) return false;
  for (const SolverInfo& known : registered())
    if (name == known.name) return false;
  registered().push_back(info);
  return true;
}

bool isRegistered(const std::string& name) {
  for (const SolverInfo& info : solvers())
    if (name == info.name) return true;
  return false;
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
  if (name.find('>') != std::string::npos) {  // a fallback chain "a>b>c"
    std::vector<std::unique_ptr<Solver>> chain;
    std::size_t start = 0;
    while (start <= name.size()) {
      const std::size_t end = std::min(name.find('>', start), name.size());
      std::unique_ptr<Solver> member = makeSolver(name.substr(start, end - start), error);
      if (!member) return nullptr;
      chain.push_back(std::move(member));
      start = end + 1;
    }
    return std::make_unique<FallbackSolver>(std::move(chain));
  }
  for (const SolverInfo& info : solvers())
    if (name == info.name) return info.make();
  if (error) *error = "unknown solver '" + name + "' (known: " + solverNames() + ")";
  return nullptr;
}

}  // namespace mlcp
