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
  bool markdown = false;
  SolverSettings settings;
};

std::string baseName(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

struct Row {
  std::string problem;
  int n = 0;
  std::string solver;
  Result result;
};

void printPlain(const std::vector<Row>& rows) {
  std::printf("%-36s %5s  %-14s %-16s %8s %11s %10s\n", "problem", "n", "solver", "status", "iter",
              "residual", "ms");
  for (const Row& row : rows)
    std::printf("%-36s %5d  %-14s %-16s %8d %11.3e %10.3f\n", row.problem.c_str(), row.n,
                row.solver.c_str(), toString(row.result.status), row.result.iterations,
                row.result.residual, row.result.seconds * 1e3);
}

// One line per problem, one column per solver; the reasons for failures listed below.
void printMarkdown(const std::vector<Row>& rows, const std::vector<std::string>& names) {
  std::printf("| problem | n |");
  for (const std::string& name : names) std::printf(" %s |", name.c_str());
  std::printf("\n|---|---|");
  for (std::size_t k = 0; k < names.size(); ++k) std::printf("---|");
  std::printf("\n");
  std::vector<std::string> notes;
  for (std::size_t i = 0; i < rows.size(); i += names.size()) {
    std::printf("| %s | %d |", rows[i].problem.c_str(), rows[i].n);
    for (std::size_t k = 0; k < names.size(); ++k) {
      const Row& row = rows[i + k];
      if (row.result.converged()) {
        std::printf(" %.0e |", row.result.residual);
      } else {
        std::printf(" **%s** |", toString(row.result.status));
        notes.push_back(row.problem + ", " + row.solver + ": " + row.result.message);
      }
    }
    std::printf("\n");
  }
  if (!notes.empty()) std::printf("\n");
  for (const std::string& note : notes) std::printf("- %s\n", note.c_str());
}

int runTable(const TableArgs& args) {
  std::vector<std::string> names = args.solvers;
  if (names.empty())
    for (const SolverInfo& info : solvers()) names.push_back(info.name);
  std::vector<Row> rows;
  int unsolved = 0;
  for (const std::string& file : args.files) {
    Problem problem;
    try {
      problem = io::readProblem(file);
    } catch (const io::UnsupportedProblem& e) {
      // A well-formed problem outside the canonical form: a row per solver saying why.
      for (const std::string& name : names) {
        Result unsupported;
        unsupported.status = Status::Unsupported;
        unsupported.message = e.what();
        rows.push_back({baseName(file), 0, name, unsupported});
        ++unsolved;
      }
      continue;
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
      applySettings(args.settings, *solver);
      Vector x;
      rows.push_back({baseName(file), problem.size(), name, solver->solve(problem, x)});
      unsolved += rows.back().result.converged() ? 0 : 1;
    }
  }
  if (args.markdown) {
    printMarkdown(rows, names);
  } else {
    printPlain(rows);
  }
  std::printf("\n%d of %zu runs did not reach the tolerance %.1e\n", unsolved, rows.size(),
              args.settings.tolerance);
  return kSolved;
}

}  // namespace

Runner addTableCommand(CLI::App& app) {
  auto args = std::make_shared<TableArgs>();
  CLI::App* cmd = app.add_subcommand(
      "table", "Run solvers on problem files and print one line per (file, solver).");
  cmd->add_option("files", args->files, "problem files (.json or Siconos .dat)")->required();
  cmd->add_option("--solvers", args->solvers, "solver names (default: all)")->delimiter(',');
  cmd->add_flag("--markdown", args->markdown,
                "a Markdown table: problems x solvers, residual or status, failure reasons below");
  addSolverSettings(*cmd, args->settings);
  return [args] { return runTable(*args); };
}

}  // namespace mlcp::cli
