// mlcp trace lemke FILE: every tableau of Lemke's method with its basis and pivots.
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "mlcp/io.hpp"
#include "mlcp/solvers/lemke.hpp"

namespace mlcp::cli {

namespace {

struct TraceArgs {
  std::string method;
  std::string file;
  int maxPivots = 0;
};

int runTrace(const TraceArgs& args) {
  if (args.method != "lemke") {
    std::cerr << "mlcp trace: only 'lemke' can be traced (got '" << args.method << "')\n";
    return kInvalidInput;
  }
  Problem problem;
  try {
    problem = io::readProblem(args.file);
  } catch (const io::FormatError& e) {
    std::cerr << "mlcp trace: " << e.what() << "\n";
    return kInvalidInput;
  }
  Options options;
  options.maxPivots = args.maxPivots;
  const Result r = traceLemke(problem, std::cout, options);
  if (r.status == Status::Unsupported || r.status == Status::InvalidInput) {
    std::cerr << "mlcp trace: " << args.file << ": " << r.message << "\n";
    return kInvalidInput;
  }
  std::cout << "status " << toString(r.status) << ": " << r.message << " (" << r.iterations
            << " pivots, residual " << r.residual << ")\n";
  return r.converged() ? kSolved : kNotSolved;
}

}  // namespace

Runner addTraceCommand(CLI::App& app) {
  auto args = std::make_shared<TraceArgs>();
  CLI::App* cmd = app.add_subcommand(
      "trace",
      "Print every tableau of a pivoting method (standard LCPs): basis labels, entering "
      "and leaving variables; exact fractions for integer input.");
  cmd->add_option("method", args->method, "the method to trace: lemke")->required();
  cmd->add_option("file", args->file, "problem file (.json or Siconos .dat)")->required();
  cmd->add_option("--max-pivots", args->maxPivots, "pivot limit (0: automatic)");
  return [args] { return runTrace(*args); };
}

}  // namespace mlcp::cli
