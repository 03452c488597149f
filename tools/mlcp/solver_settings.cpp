#include "solver_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include "mlcp/input_limits.hpp"
#include "mlcp/island/fallback.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/solvers/dantzig.hpp"
#include "mlcp/solvers/lemke.hpp"
#include "mlcp/solvers/newton.hpp"
#include "mlcp/solvers/proximal.hpp"

namespace mlcp::cli {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMaxCount = 1e9;  // whole-number parameters: counts, rows, steps

NewtonParams* newtonOf(Solver& s) {
  auto* n = dynamic_cast<NewtonSolver*>(&s);
  return n ? &n->params() : nullptr;
}
DantzigParams* dantzigOf(Solver& s) {
  auto* d = dynamic_cast<DantzigSolver*>(&s);
  return d ? &d->params() : nullptr;
}
LemkeSolver* lemkeOf(Solver& s) { return dynamic_cast<LemkeSolver*>(&s); }
ProximalParams* proximalOf(Solver& s) {
  auto* p = dynamic_cast<ProximalSolver*>(&s);
  return p ? &p->params() : nullptr;
}

// The accessors of one field of the parameters `Of` finds in a solver.
template <auto Of, auto Field>
double getField(Solver& s) {
  auto* owner = Of(s);
  return owner ? static_cast<double>(owner->*Field) : kNaN;
}
template <auto Of, auto Field>
void setField(Solver& s, double v) {
  auto* owner = Of(s);
  if (!owner) return;
  using T = std::remove_reference_t<decltype(owner->*Field)>;
  if constexpr (std::is_same_v<T, bool>)
    owner->*Field = v != 0;
  else
    owner->*Field = static_cast<T>(v);
}

// The values a parameter takes: whole counts (>= 0, >= 1), non-negative, positive numbers, a
// number in (0, 1], a flag.
struct Range {
  bool whole;
  double lo, hi;
  const char* words;
};
constexpr Range kCount{true, 0, kMaxCount, ">= 0"};
constexpr Range kCountFrom1{true, 1, kMaxCount, ">= 1"};
constexpr Range kNonNegative{false, 0, 1e300, ">= 0"};
constexpr Range kPositive{false, 1e-300, 1e300, "> 0"};
constexpr Range kFraction{false, 1e-300, 1, "in (0, 1]"};
constexpr Range kFlag{true, 0, 1, "0 or 1 (false or true)"};

template <auto Of, auto Field>
SolverParam param(const char* solver, const char* name, const Range& r, const char* help) {
  return {
      solver, name, r.whole, r.lo, r.hi, r.words, help, &getField<Of, Field>, &setField<Of, Field>};
}

std::vector<SolverParam> newtonParams() {
  constexpr auto N = &newtonOf;
  using P = NewtonParams;
  const char* s = "newton";
  return {
      param<N, &P::coldSweeps>(s, "cold_sweeps", kCount, "pgs sweeps over a cold start"),
      param<N, &P::warmSweeps>(s, "warm_sweeps", kCount, "pgs sweeps over a far warm start"),
      param<N, &P::warmSweepsResidual>(s, "warm_sweeps_residual", kNonNegative,
                                       "a warm start's residual above which it is swept"),
      param<N, &P::denseFactorMaxRows>(s, "dense_factor_max_rows", kCount,
                                       "most rows of the dense LU"),
      param<N, &P::proximal>(s, "proximal", kPositive, "the proximal weight's start"),
      param<N, &P::proximalMax>(s, "proximal_max", kPositive,
                                "the proximal weight's largest value"),
      param<N, &P::maxHalvings>(s, "max_halvings", kCount, "line search halvings, dense path"),
      param<N, &P::sparseMaxHalvings>(s, "sparse_max_halvings", kCount,
                                      "line search halvings, sparse path"),
      param<N, &P::stepSweeps>(s, "step_sweeps", kCount, "pgs sweeps of the fallback step"),
      param<N, &P::maxStalls>(s, "max_stalls", kCount, "steps in a row without descent"),
      param<N, &P::maxStagnation>(s, "max_stagnation", kCount, "steps in a row without a new best"),
      param<N, &P::nonmonotoneMemory>(s, "nonmonotone_memory", kCount,
                                      "merits the line search compares with (0: monotone)"),
      param<N, &P::pivotingSteps>(s, "pivoting_steps", kCount,
                                  "block pivoting steps after damped steps end short (0: none)"),
      param<N, &P::bodyPivotingSteps>(s, "body_pivoting_steps", kCount,
                                      "the same on an engine's rows (body space)"),
      param<N, &P::pivotingWoodburyRows>(s, "pivoting_woodbury_rows", kCount,
                                         "most sliding rows solved by Woodbury"),
      param<N, &P::pivotingUpdateRows>(s, "pivoting_update_rows", kCount,
                                       "most changed rows for a factor update (0: refactor)"),
      param<N, &P::pivotingDescentSteps>(s, "pivoting_descent_steps", kCount,
                                         "descending block steps not counted as stalls"),
      param<N, &P::pivotingBreakCycles>(s, "pivoting_break_cycles", kFlag,
                                        "a 2-cycle of index sets hands over to damped steps"),
  };
}

std::vector<SolverParam> dantzigAndLemkeParams() {
  constexpr auto D = &dantzigOf;
  constexpr auto L = &lemkeOf;
  using P = DantzigParams;
  return {
      param<D, &P::breakdownShift>("dantzig", "breakdown_shift", kNonNegative,
                                   "shift of the retry after a breakdown, x max A_ii"),
      param<D, &P::andersonDepth>("dantzig", "anderson_depth", kCount,
                                  "normals' history of Anderson's extrapolation (friction)"),
      param<D, &P::andersonStall>("dantzig", "anderson_stall", kCount,
                                  "passes without gain before damped iteration"),
      param<D, &P::stallDamping>("dantzig", "stall_damping", kFraction,
                                 "damping factor of that iteration"),
      param<L, &LemkeSolver::denseRows>("lemke", "dense_rows", kCount,
                                        "most rows of the dense tableau"),
      param<L, &LemkeSolver::refactorPeriod>("lemke", "refactor_period", kCountFrom1,
                                             "pivots between refactorizations of the basis"),
      param<L, &LemkeSolver::maxRows>("lemke", "max_rows", kCountFrom1,
                                      "largest problem accepted, rows"),
      param<L, &LemkeSolver::frictionLcp>("lemke", "friction_lcp", kFlag,
                                          "findex friction as one LCP (0: the fixed point)"),
  };
}

std::vector<SolverParam> proximalParams() {
  constexpr auto X = &proximalOf;
  using P = ProximalParams;
  const char* s = "proximal";
  return {
      param<X, &P::sigma>(s, "sigma", kPositive, "alpha = sigma r^nu mean(A_ii)"),
      param<X, &P::nu>(s, "nu", kPositive, "the residual's power in alpha"),
      param<X, &P::alphaMin>(s, "alpha_min", kPositive, "smallest alpha / mean(A_ii)"),
      param<X, &P::alphaMax>(s, "alpha_max", kPositive, "largest alpha / mean(A_ii)"),
      param<X, &P::alphaGrowth>(s, "alpha_growth", kPositive,
                                "factor on alpha after an inner solve ended short"),
      param<X, &P::innerFactor>(s, "inner_factor", kPositive,
                                "inner tolerance = max(tol / 10, this x residual)"),
      param<X, &P::maxOuter>(s, "max_outer", kCount, "most outer steps"),
  };
}

// Options' numeric fields and their accepted values (tol and max_iter as `mlcp solve` checks
// them: the same words).
struct SettingCheck {
  const char* name;
  double (*get)(const SolverSettings&);
  bool whole;
  double lo, hi;
  const char* range;
};
const SettingCheck kSettingChecks[] = {
    {"tol", [](const SolverSettings& s) { return s.tolerance; }, false, 1e-300, 1e300,
     "in [1e-300, 1e300]"},
    {"max_iter", [](const SolverSettings& s) { return double(s.maxIterations); }, false, 0, 1e300,
     "in [0, 1e300]"},
    {"time_budget", [](const SolverSettings& s) { return s.timeBudget; }, false, 0, 1e300, ">= 0"},
    {"max_pivots", [](const SolverSettings& s) { return double(s.maxPivots); }, true, 0, kMaxCount,
     ">= 0"},
    {"check_every", [](const SolverSettings& s) { return double(s.checkEvery); }, true, 1,
     kMaxCount, ">= 1"},
    {"pivot_tolerance", [](const SolverSettings& s) { return s.pivotTolerance; }, false, 0, 1,
     "in [0, 1]"},
};

std::string spelled(const char* name, bool kebab) {
  std::string s(name);
  if (kebab) std::replace(s.begin(), s.end(), '_', '-');
  return s;
}

// Levenshtein's: the fewest single-character edits from a to b.
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// The shortest decimal that reads back as v (0.2, not 0.20000000000000001).
std::string formatValue(double v) {
  char buf[32];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

}  // namespace

const std::vector<SolverParam>& solverParams() {
  static const std::vector<SolverParam> all = [] {
    std::vector<SolverParam> v = newtonParams();
    for (const SolverParam& p : dantzigAndLemkeParams()) v.push_back(p);
    for (const SolverParam& p : proximalParams()) v.push_back(p);
    return v;
  }();
  return all;
}

std::string paramSolverNames() { return "newton, dantzig, lemke, proximal"; }

std::string paramList(const std::string& solver, bool kebab) {
  const std::unique_ptr<Solver> fresh = makeSolver(solver);
  std::string out;
  for (const SolverParam& p : solverParams()) {
    if (solver != p.solver) continue;
    const double v = fresh ? p.get(*fresh) : kNaN;
    const bool flag = p.whole && p.lo == 0 && p.hi == 1;
    out += (out.empty() ? "" : ", ") + spelled(p.name, kebab) + " (" +
           (flag ? (v != 0 ? "true" : "false") : formatValue(v)) + ")";
  }
  return out;
}

std::string rangeError(double value, const std::string& text, bool whole, double lo, double hi,
                       const std::string& range) {
  if (std::isfinite(value) && value >= lo && value <= hi && (!whole || value == std::floor(value)))
    return "";
  return std::string("expected ") + (whole ? "a whole number " : "a number ") + range + ", got '" +
         io::capped(text, 24) + "'";
}

void setSolverParam(SolverSettings& s, const std::string& solver, const std::string& key,
                    double value, const std::string& text, bool kebab) {
  const auto& all = solverParams();
  if (std::none_of(all.begin(), all.end(),
                   [&](const SolverParam& p) { return solver == p.solver; }))
    throw std::invalid_argument("unknown solver '" + io::capped(solver, 24) +
                                "' for parameters (known: " + paramSolverNames() + ")");
  std::string name = key;
  std::replace(name.begin(), name.end(), '-', '_');
  for (const SolverParam& p : all) {
    if (solver != p.solver || name != p.name) continue;
    const std::string error = rangeError(value, text, p.whole, p.lo, p.hi, p.range);
    if (!error.empty()) throw std::invalid_argument(io::capped(key, 40) + ": " + error);
    s.params.emplace_back(&p, value);
    return;
  }
  std::string known;
  const SolverParam* closest = nullptr;
  std::size_t distance = 0;
  for (const SolverParam& p : all) {
    if (solver != p.solver) continue;
    known += (known.empty() ? "" : ", ") + spelled(p.name, kebab);
    const std::size_t d = editDistance(name, p.name);
    if (!closest || d < distance) closest = &p, distance = d;
  }
  throw std::invalid_argument("unknown parameter '" + io::capped(key, 40) +
                              "' (closest: " + spelled(closest->name, kebab) +
                              (kebab ? "" : "; known: " + known) + ")");
}

void setSolverParam(SolverSettings& s, const std::string& solver, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos)
    throw std::invalid_argument("expected KEY=VALUE, got '" + io::capped(assignment, 40) + "'");
  const std::string key = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  double value = kNaN;
  if (text == "true" || text == "false") {
    value = text == "true" ? 1 : 0;
  } else {
    value = io::parseNumber(text);
  }
  setSolverParam(s, solver, key, value, text, true);
}

std::string settingError(const std::string& name, double value, const std::string& text) {
  if (name == "friction_bounds")
    return text == "exact" || text == "fixed-once"
               ? ""
               : "expected exact or fixed-once, got '" + io::capped(text, 24) + "'";
  for (const SettingCheck& c : kSettingChecks)
    if (name == c.name) return rangeError(value, text, c.whole, c.lo, c.hi, c.range);
  return "";
}

void checkSettings(const SolverSettings& s) {
  for (const SettingCheck& c : kSettingChecks) {
    const double value = c.get(s);
    const std::string error = settingError(c.name, value, formatValue(value));
    if (!error.empty()) throw std::invalid_argument(std::string(c.name) + ": " + error);
  }
  const std::string error = settingError("friction_bounds", kNaN, s.frictionBounds);
  if (!error.empty()) throw std::invalid_argument("friction_bounds: " + error);
}

void applySettings(const SolverSettings& s, Solver& solver) {
  Options& o = solver.options();
  o.tolerance = s.tolerance;
  o.maxIterations = s.maxIterations;
  o.relaxation = s.relaxation;
  o.timeBudget = s.timeBudget;
  o.maxPivots = s.maxPivots;
  o.checkEvery = s.checkEvery;
  o.pivotTolerance = s.pivotTolerance;
  o.frictionBounds =
      s.frictionBounds == "fixed-once" ? FrictionBounds::FixedOnce : FrictionBounds::Exact;
  if (s.params.empty()) return;
  for (const auto& [param, value] : s.params) param->set(solver, value);
  if (auto* chain = dynamic_cast<FallbackSolver*>(&solver))
    for (const std::unique_ptr<Solver>& member : chain->chain()) applySettings(s, *member);
  if (auto* automatic = dynamic_cast<AutoSolver*>(&solver))
    automatic->configure = [s](Solver& made) { applySettings(s, made); };
}

}  // namespace mlcp::cli
