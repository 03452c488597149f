// The `mlcp` program's subcommands. Each registers itself on the CLI11 app and runs after
// parsing; exit codes: 0 solved to tolerance, 1 not solved (or failed), 2 invalid input.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "mlcp/result.hpp"
#include "solver_settings.hpp"

namespace mlcp::cli {

enum ExitCode { kSolved = 0, kNotSolved = 1, kInvalidInput = 2 };

// Adds the subcommand; the returned function runs it (call it only if the subcommand parsed).
using Runner = std::function<int()>;
Runner addSolveCommand(CLI::App& app);
Runner addTableCommand(CLI::App& app);
Runner addTraceCommand(CLI::App& app);
Runner addRunCommand(CLI::App& app);
Runner addStabilityCommand(CLI::App& app);
Runner addDiffCommand(CLI::App& app);
Runner addSweepCommand(CLI::App& app);
Runner addChartCommand(CLI::App& app);
// Runs tools/chart.py with these arguments (what `mlcp chart` does); returns its exit code
// (1: no Python or script).
int runChart(const std::vector<std::string>& args);

// The options of the solver settings (solver_settings.hpp), shared by solve and table: --tol,
// --max-iter, --relaxation, --time-budget, --max-pivots, --check-every, --pivot-tolerance,
// --friction-bounds, and the typed parameters as --newton / --dantzig / --lemke KEY=VALUE,...
void addSolverSettings(CLI::App& cmd, SolverSettings& s);

// Option checks with one-line messages that echo at most a few characters of the value
// (CLI11's own PositiveNumber / NonNegativeNumber print their bounds with 309 digits):
// a number in [1e-300, 1e300] (positive), or in [0, 1e300] (non-negative).
CLI::Validator positiveNumber();
CLI::Validator nonNegativeNumber();

}  // namespace mlcp::cli
