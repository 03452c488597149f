// mlcp solve FILE --solver NAME [--tol T] [--max-iter N] [--guess X.json] [--json]
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "mlcp/input_limits.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"

namespace mlcp::cli {

namespace {

CLI::Validator numberIn(double lo, double hi, const std::string& range) {
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        std::size_t used = 0;
        double v = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != 0 && used == text.size() && v >= lo && v <= hi) return "";
        return "expected a number in " + range + ", got '" + io::capped(text, 24) + "'";
      },
      range);
}

}  // namespace

CLI::Validator positiveNumber() { return numberIn(1e-300, 1e300, "[1e-300, 1e300]"); }
CLI::Validator nonNegativeNumber() { return numberIn(0, 1e300, "[0, 1e300]"); }

void addSolverSettings(CLI::App& cmd, SolverSettings& s) {
  cmd.add_option("--tol", s.tolerance, "target scaled natural-map residual")
      ->check(positiveNumber())
      ->capture_default_str();
  cmd.add_option("--max-iter", s.maxIterations,
                 "iteration limit (sweeps; outer iterations of pivoting methods)")
      ->check(nonNegativeNumber())
      ->capture_default_str();
  cmd.add_option("--relaxation", s.relaxation, "SOR factor of gs/pgs, in (0, 2)")
      ->capture_default_str();
  cmd.add_option("--time-budget", s.timeBudget,
                 "wall-clock budget of a solve in seconds, 0 for none: when it runs out the "
                 "best answer so far is returned with status time-limit")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

void applySettings(const SolverSettings& s, Options& options) {
  options.tolerance = s.tolerance;
  options.maxIterations = s.maxIterations;
  options.relaxation = s.relaxation;
  options.timeBudget = s.timeBudget;
}

namespace {

struct SolveArgs {
  std::string file;
  std::string solver = "pgs";
  std::string guess;
  bool json = false;
  SolverSettings settings;
};

nlohmann::json toJsonArray(const Vector& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (std::isfinite(v[i]))
      a.push_back(v[i]);
    else
      a.push_back(nullptr);  // JSON has no NaN/Inf
  }
  return a;
}

int runSolve(const SolveArgs& args) {
  std::string error;
  std::unique_ptr<Solver> solver = makeSolver(args.solver, &error);
  if (!solver) {
    std::cerr << "mlcp solve: " << error << "\n";
    return kInvalidInput;
  }
  Problem problem;
  Vector guess;
  try {
    problem = io::readProblem(args.file);
    if (!args.guess.empty()) guess = io::readVectorJson(args.guess);
  } catch (const io::FormatError& e) {
    std::cerr << "mlcp solve: " << e.what() << "\n";
    return kInvalidInput;
  }
  Options& opt = solver->options();
  applySettings(args.settings, opt);
  Vector x;
  Result r =
      args.guess.empty() ? solver->solve(problem, x) : solver->solveWithGuess(problem, guess, x);
  if (r.status == Status::InvalidInput) {
    std::cerr << "mlcp solve: " << args.file << ": " << r.message << "\n";
    return kInvalidInput;
  }
  const Vector w = x.size() == problem.size() ? problem.slack(x) : Vector();
  if (args.json) {
    nlohmann::json out = {{"solver", solver->name()},
                          {"status", toString(r.status)},
                          {"message", r.message},
                          {"x", toJsonArray(x)},
                          {"w", toJsonArray(w)},
                          {"iterations", r.iterations},
                          {"residual", r.residual},
                          {"complementarity", r.complementarity},
                          {"bound_violation", r.boundViolation},
                          {"seconds", r.seconds}};
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("file        %s (n = %d, %s, %s)\n", args.file.c_str(), problem.size(),
                toString(problem.classify()), problem.isSparse() ? "sparse" : "dense");
    std::printf("solver      %s\n", solver->name());
    std::printf("status      %s: %s\n", toString(r.status), r.message.c_str());
    std::printf("iterations  %d\n", r.iterations);
    std::printf("residual    %.3e (tolerance %.1e)\n", r.residual, opt.tolerance);
    std::printf("compl.      %.3e\n", r.complementarity);
    std::printf("seconds     %.6f\n", r.seconds);
    if (x.size() <= 20) {
      std::printf("x          ");
      for (Eigen::Index i = 0; i < x.size(); ++i) std::printf(" %.12g", x[i]);
      std::printf("\n");
    }
  }
  return r.converged() ? kSolved : kNotSolved;
}

}  // namespace

Runner addSolveCommand(CLI::App& app) {
  auto args = std::make_shared<SolveArgs>();
  CLI::App* cmd = app.add_subcommand(
      "solve",
      "Solve a problem file (mlcp-problem/1 .json or Siconos LCP .dat).\nExit 0: solved "
      "to tolerance; 1: not solved; 2: invalid input.");
  cmd->add_option("file", args->file, "problem file")->required();
  cmd->add_option("--solver", args->solver, "solver: " + solverNames())->capture_default_str();
  cmd->add_option("--guess", args->guess, "start point: JSON array (or object with \"x\")");
  cmd->add_flag("--json", args->json,
                "print {solver, status, x, w, iterations, residual, seconds, ...} as JSON");
  addSolverSettings(*cmd, args->settings);
  return [args] { return runSolve(*args); };
}

}  // namespace mlcp::cli
