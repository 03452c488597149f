// mlcp solve FILE --solver NAME [--tol T] [--max-iter N] [--guess X.json] [--json]: one problem
// file solved, with every solver setting of solver_settings.hpp (Options' fields and the typed
// parameters, e.g. --newton pivoting-steps=0,cold-sweeps=0).
#include <cmath>
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
        const double v = io::parseNumber(text);
        if (v >= lo && v <= hi) return "";
        return "expected a number in " + range + ", got '" + io::capped(text, 24) + "'";
      },
      range);
}

}  // namespace

CLI::Validator positiveNumber() { return numberIn(1e-300, 1e300, "[1e-300, 1e300]"); }
CLI::Validator nonNegativeNumber() { return numberIn(0, 1e300, "[0, 1e300]"); }

namespace {

// An option of Options' fields checked as solver_settings.hpp checks them (Python's name).
CLI::Validator settingCheck(const std::string& name) {
  return CLI::Validator(
      [name](std::string& text) -> std::string {
        return settingError(name, io::parseNumber(text), text);
      },
      "");
}

// --newton / --dantzig / --lemke KEY=VALUE,...: each assignment checked as it is parsed.
void addParamOption(CLI::App& cmd, SolverSettings& s, const std::string& solver) {
  cmd.add_option_function<std::vector<std::string>>(
         "--" + solver,
         [&s, solver](const std::vector<std::string>& list) {
           for (const std::string& a : list) setSolverParam(s, solver, a);
         },
         solver + "'s parameters, KEY=VALUE,... (a flag: true or false; wherever " + solver +
             " runs: named, in a chain or chosen by auto), with their defaults: " +
             paramList(solver, true))
      ->delimiter(',')
      ->check(CLI::Validator(
          [solver](std::string& a) -> std::string {
            SolverSettings scratch;
            try {
              setSolverParam(scratch, solver, a);
            } catch (const std::invalid_argument& e) {
              return e.what();
            }
            return "";
          },
          "KEY=VALUE"));
}

}  // namespace

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
  cmd.add_option("--max-pivots", s.maxPivots,
                 "pivot limit of pivoting methods (per friction pass for dantzig), 0: 50 n + 100")
      ->check(settingCheck("max_pivots"))
      ->capture_default_str();
  cmd.add_option("--check-every", s.checkEvery,
                 "iterative methods check the residual every this many sweeps")
      ->check(settingCheck("check_every"))
      ->capture_default_str();
  cmd.add_option("--pivot-tolerance", s.pivotTolerance,
                 "pivots below this (relative to max A_ii) count as zero, in [0, 1]")
      ->check(settingCheck("pivot_tolerance"))
      ->capture_default_str();
  cmd.add_option("--friction-bounds", s.frictionBounds,
                 "friction rows' bounds: exact, or fixed-once (fixed from an intermediate "
                 "normal, as stock ODE and Bullet do)")
      ->check(settingCheck("friction_bounds"))
      ->capture_default_str();
  for (const char* solver : {"newton", "dantzig", "lemke", "proximal"})
    addParamOption(cmd, s, solver);
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
  const Options& opt = solver->options();
  applySettings(args.settings, *solver);
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
