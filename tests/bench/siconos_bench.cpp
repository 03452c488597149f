// siconos_bench: our solvers and Siconos numerics' on the same captured engine islands.
//
//     siconos_bench [--tol 1e-6] [--max-iter 1000] [--time-limit 60] [--max-dense-rows 6000]
//                   [--repeat 1] [--csv OUT.csv] ISLAND.json...
//
// Each island (mlcp-problem/1 from `mlcp run --capture`) is solved in up to three forms
// (island_forms.hpp):
//   findex  the island as the engine hands it over: ours only (Siconos has no findex);
//   lcp     its frictionless LCP: ours and Siconos' lcp_newton_FB, lcp_newton_min,
//           lcp_newton_minFB, lcp_lexicolemke, lcp_pgs;
//   boxed   its friction bounds fixed at the normals of the reference answer (the lowest residual
//           of our answers to the findex form): ours and Siconos' relay_pgs, relay_lexicolemke,
//           relay_avi_caoferris, all three on the box with its infinite bounds capped at
//           10 (1 + |x_ref|_inf) (relay Lemke needs ub - lb finite).
// Ours: pgs, dantzig, newton, lemke and auto from the registry, tolerance --tol, --max-iter
// sweeps / Newton steps / friction passes, --time-limit as their time budget. Siconos': as
// siconos_solvers.hpp says (tolerance matched, each solve in a child process with the same
// wall-clock limit). --repeat R: every solve is done R times from zero (ours by the same solver
// object, its workspaces kept; Siconos' in the same child) and ms is the median, for problems of a
// few rows whose single solve is below the clock's noise. Every answer's residual is ours
// (residual.hpp), computed here; `status` is converged exactly when it meets --tol. Solvers that
// need A dense (Siconos', our lemke) are skipped above --max-dense-rows rows (relay Lemke: above
// half of it, it doubles the problem).
//
// One CSV row per (island, form, solver):
//   island,form,rows,solver,library,ms,iterations,residual,findex_residual,status,
//   siconos_error,siconos_info,note
// findex_residual: the boxed form's answer measured on the findex problem (how far fixing the
// bounds at x_ref's normals held). Exit 0: every island was read; 2: bad arguments or a file
// that is not a problem.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <vector>

#include "island_forms.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "siconos_solvers.hpp"

// OpenBLAS, where Siconos runs on it, may start threads; our solvers run on one core, and so does
// every Siconos solve here (weak: absent with another BLAS).
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace {

using namespace mlcp;
using namespace mlcp::bench;

struct Settings {
  double tolerance = 1e-6;
  int maxIterations = 1000;
  double seconds = 60;
  int maxDenseRows = 6000;
  int repeat = 1;
};

struct Row {
  std::string island, form, solver, library, status, note;
  int rows = 0, iterations = 0, siconosInfo = 0;
  double ms = 0, residual = kNotComputed, findexResidual = kNotComputed,
         siconosError = kNotComputed;
  bool siconos = false;  // a Siconos solver returned: siconos_error and siconos_info hold its own
};

std::string number(double v) {
  if (std::isnan(v)) return "";
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

// A CSV field: in double quotes (doubled inside) when it holds a comma or a quote.
std::string quoted(const std::string& text) {
  if (text.find_first_of(",\"") == std::string::npos) return text;
  std::string q = "\"";
  for (char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

class Report {
 public:
  explicit Report(std::ostream* csv) : csv_(csv) {
    if (csv_)
      *csv_ << "island,form,rows,solver,library,ms,iterations,residual,findex_residual,status,"
               "siconos_error,siconos_info,note\n";
  }
  void add(const Row& r) {
    const std::string info = r.siconos ? std::to_string(r.siconosInfo) : "";
    if (csv_)
      *csv_ << r.island << ',' << r.form << ',' << r.rows << ',' << r.solver << ',' << r.library
            << ',' << number(r.ms) << ',' << r.iterations << ',' << number(r.residual) << ','
            << number(r.findexResidual) << ',' << r.status << ',' << number(r.siconosError) << ','
            << info << ',' << quoted(r.note) << '\n';
    std::printf("%-40s %-6s %6d %-20s %10.3f ms %6d it  residual %-10s %s%s%s\n", r.island.c_str(),
                r.form.c_str(), r.rows, r.solver.c_str(), r.ms, r.iterations,
                number(r.residual).c_str(), r.status.c_str(), r.note.empty() ? "" : "  ",
                r.note.c_str());
    std::fflush(stdout);
  }

 private:
  std::ostream* csv_;
};

const char* kOurs[] = {"pgs", "dantzig", "newton", "lemke", "auto"};

// One of our solvers on `p`; x receives the answer.
Row solveOurs(const std::string& name, const Problem& p, const Settings& s, Vector& x) {
  Row row;
  row.solver = name;
  row.library = "mlcp";
  row.rows = p.size();
  if (name == "lemke" && p.size() > s.maxDenseRows) {
    row.status = "skipped";
    row.note = "dense; rows > --max-dense-rows";
    return row;
  }
  std::unique_ptr<Solver> solver = makeSolver(name);
  solver->options().tolerance = s.tolerance;
  solver->options().maxIterations = s.maxIterations;
  solver->options().timeBudget = s.seconds;
  Result r;
  std::vector<double> ms;
  for (int k = 0; k < s.repeat; ++k) {  // from zero every time (options().warmStart is off)
    const double t0 = nowSeconds();
    r = solver->solve(p, x);
    ms.push_back((nowSeconds() - t0) * 1e3);
  }
  std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
  row.ms = ms[ms.size() / 2];
  row.iterations = r.iterations;
  row.status = toString(r.status);
  if (x.size() != p.size()) {  // nothing solved (unsupported, invalid input): no answer to measure
    row.note = r.message;
    return row;
  }
  row.residual = residual(p, x);  // recomputed here, whatever the solver reported
  if (row.residual <= s.tolerance)
    row.status = "converged";
  else if (r.status == Status::Converged)
    row.status = "failed";
  if (r.solver != name && !r.solver.empty()) row.note = "answered by " + r.solver;
  return row;
}

// One Siconos solver on `given` (what it is handed), measured on `measured`; x receives the
// answer (empty when there is none).
Row solveSiconos(const SiconosSolverInfo& info, const Problem& given, const Problem& measured,
                 const Settings& s, Vector& x) {
  Row row;
  row.solver = info.name;
  row.library = "siconos";
  row.rows = given.size();
  if (given.size() * info.sizeFactor > s.maxDenseRows) {
    row.status = "skipped";
    row.note = "dense; rows > the dense limit";
    return row;
  }
  const SiconosOutcome out = solveWithSiconos(
      info, given, SiconosLimits{s.tolerance, s.maxIterations, s.seconds, s.repeat});
  if (out.end != SiconosOutcome::End::Returned) {
    row.status = out.end == SiconosOutcome::End::TimeLimit ? "time-limit" : "crashed";
    row.ms = out.end == SiconosOutcome::End::TimeLimit ? s.seconds * 1e3 : 0;
    row.note = out.message;
    return row;
  }
  row.siconos = true;  // its counters are reported
  row.ms = out.ms;
  row.iterations = out.iterations;
  row.siconosInfo = out.info;
  row.siconosError = out.ownError;
  x = out.z;
  row.residual = residual(measured, x);
  row.status = row.residual <= s.tolerance ? "converged" : "not-converged";
  return row;
}

// Our solvers on the findex form; returns the answer with the lowest residual (the reference).
Vector solveFindex(const std::string& island, const Problem& p, const Settings& s, Report& report,
                   std::string* from) {
  Vector best;
  double bestResidual = kInf;
  for (const char* name : kOurs) {
    Vector x;
    Row row = solveOurs(name, p, s, x);
    row.island = island;
    row.form = "findex";
    row.findexResidual = row.residual;
    report.add(row);
    if (row.status != "skipped" && row.residual < bestResidual) {
      bestResidual = row.residual;
      best = x;
      *from = std::string(name) + " (residual " + number(row.residual) + ")";
    }
  }
  return best;
}

void solveLcp(const std::string& island, const Problem& lcp, const Settings& s, Report& report) {
  for (const char* name : kOurs) {
    Vector x;
    Row row = solveOurs(name, lcp, s, x);
    row.island = island;
    row.form = "lcp";
    report.add(row);
  }
  for (const SiconosSolverInfo& info : siconosSolvers()) {
    if (info.form != SiconosForm::Lcp) continue;
    Vector x;
    Row row = solveSiconos(info, lcp, lcp, s, x);
    row.island = island;
    row.form = "lcp";
    report.add(row);
  }
}

// The box `box` (friction bounds fixed from the reference `from`), measured also on `findex`.
void solveBox(const std::string& island, const Problem& box, const Problem& findex,
              const Vector& reference, const std::string& from, const Settings& s, Report& report) {
  const std::string note = from.empty() ? "" : "bounds from " + from;
  const auto finish = [&](Row row, const Vector& x) {
    row.island = island;
    row.form = "boxed";
    if (x.size() == findex.size()) row.findexResidual = residual(findex, x);
    if (row.note.empty()) row.note = note;
    report.add(row);
  };
  for (const char* name : kOurs) {
    Vector x;
    finish(solveOurs(name, box, s, x), x);
  }
  const double cap = 10 * (1 + (reference.size() ? reference.lpNorm<Eigen::Infinity>() : 0.0));
  const Problem capped = cappedBox(box, cap);
  for (const SiconosSolverInfo& info : siconosSolvers()) {
    if (info.form != SiconosForm::Relay) continue;
    Vector x;
    finish(solveSiconos(info, capped, box, s, x), x);
  }
}

void solveIsland(const std::string& path, const Settings& s, Report& report) {
  const Problem island = io::readProblem(path);
  std::string name = path.substr(path.find_last_of('/') + 1);
  if (name.size() > 5 && name.substr(name.size() - 5) == ".json") name.resize(name.size() - 5);
  std::string from;
  Vector reference;
  if (island.hasFindex()) reference = solveFindex(name, island, s, report, &from);
  std::string why;
  if (const auto lcp = frictionlessLcp(island, &why))
    solveLcp(name, *lcp, s, report);
  else
    std::printf("%s: no frictionless LCP form (%s)\n", name.c_str(), why.c_str());
  if (island.hasFindex())
    solveBox(name, fixedBoundBox(island, reference), island, reference, from, s, report);
  else if (island.classify() == ProblemClass::Boxed)
    solveBox(name, island, island, Vector(), "", s, report);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Our solvers and Siconos numerics' on the same captured islands (mlcp-problem/1): "
      "one CSV row per island, form (findex, lcp, boxed) and solver"};
  Settings s;
  std::vector<std::string> files;
  std::string csvPath;
  app.add_option("--tol", s.tolerance, "tolerance of our scaled residual (default 1e-6)")
      ->check(CLI::PositiveNumber);
  app.add_option("--max-iter", s.maxIterations,
                 "PGS sweeps, Newton steps, friction passes (default 1000)")
      ->check(CLI::PositiveNumber);
  app.add_option("--time-limit", s.seconds, "wall-clock limit of one solve in s (default 60)")
      ->check(CLI::PositiveNumber);
  app.add_option("--max-dense-rows", s.maxDenseRows,
                 "largest problem handed to a dense solver (default 6000)")
      ->check(CLI::PositiveNumber);
  app.add_option("--repeat", s.repeat, "solves of each problem; ms is their median (default 1)")
      ->check(CLI::PositiveNumber);
  app.add_option("--csv", csvPath, "CSV file to write");
  app.add_option("islands", files, "problem files (mlcp-problem/1)")->required();
  CLI11_PARSE(app, argc, argv);
  if (openblas_set_num_threads) openblas_set_num_threads(1);
  std::ofstream csv;
  if (!csvPath.empty()) {
    csv.open(csvPath);
    if (!csv) {
      std::fprintf(stderr, "siconos_bench: cannot write %s\n", csvPath.c_str());
      return 2;
    }
  }
  Report report(csvPath.empty() ? nullptr : &csv);
  try {
    for (const std::string& f : files) solveIsland(f, s, report);
  } catch (const io::FormatError& e) {
    std::fprintf(stderr, "siconos_bench: %s\n", e.what());
    return 2;
  }
  return 0;
}
