// mlcp table FILES... [--solvers a,b]: every solver on every file, one line each.
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"

namespace mlcp::cli {

namespace {

struct TableArgs {
  std::vector<std::string> files;
  std::vector<std::string> solvers;
  SolverSettings settings;
};

std::string baseName(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

int runTable(const TableArgs& args) {
  std::vector<std::string> names = args.solvers;
  if (names.empty())
    for (const SolverInfo& info : solvers()) names.push_back(info.name);
  int unsolved = 0;
  std::printf("%-36s %5s  %-8s %-16s %8s %11s %10s\n", "problem", "n", "solver", "status", "iter",
              "residual", "ms");
  for (const std::string& file : args.files) {
    Problem problem;
    try {
      problem = io::readProblem(file);
    } catch (const io::FormatError& e) {
      std::fprintf(stderr, "mlcp table: %s\n", e.what());
      return kInvalidInput;
    }
    for (const std::string& name : names) {
      std::string error;
      std::unique_ptr<Solver> solver = makeSolver(name, &error);
      if (!solver) {
        std::fprintf(stderr, "mlcp table: %s\n", error.c_str());
        return kInvalidInput;
      }
      solver->options().tolerance = args.settings.tolerance;
      solver->options().maxIterations = args.settings.maxIterations;
      solver->options().relaxation = args.settings.relaxation;
      Vector x;
      const Result r = solver->solve(problem, x);
      unsolved += r.converged() ? 0 : 1;
      std::printf("%-36s %5d  %-8s %-16s %8d %11.3e %10.3f\n", baseName(file).c_str(),
                  problem.size(), name.c_str(), toString(r.status), r.iterations, r.residual,
                  r.seconds * 1e3);
    }
  }
  std::printf("%d of %zu runs did not reach the tolerance %.1e\n", unsolved,
              args.files.size() * names.size(), args.settings.tolerance);
  return kSolved;
}

}  // namespace

Runner addTableCommand(CLI::App& app) {
  auto args = std::make_shared<TableArgs>();
  CLI::App* cmd = app.add_subcommand(
      "table", "Run solvers on problem files and print one line per (file, solver).");
  cmd->add_option("files", args->files, "problem files (.json or Siconos .dat)")->required();
  cmd->add_option("--solvers", args->solvers, "solver names (default: all)")->delimiter(',');
  addSolverSettings(*cmd, args->settings);
  return [args] { return runTable(*args); };
}

}  // namespace mlcp::cli
