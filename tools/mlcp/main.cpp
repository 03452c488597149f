// mlcp: solve problem files, compare solvers. `mlcp --help` lists the subcommands.
#include <iostream>
#include <vector>

#include "commands.hpp"
#include "mlcp/input_limits.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/scene/world.hpp"

int main(int argc, char** argv) {
  CLI::App app{"mlcp: mixed linear complementarity solvers for physics engines.\nSolvers: " +
               mlcp::solverNames()};
  app.require_subcommand(1);
  std::vector<std::pair<CLI::App*, mlcp::cli::Runner>> commands;
  auto add = [&](mlcp::cli::Runner (*adder)(CLI::App&)) {
    const std::size_t before = app.get_subcommands({}).size();
    mlcp::cli::Runner run = adder(app);
    commands.emplace_back(app.get_subcommands({}).at(before), std::move(run));
  };
  add(&mlcp::cli::addSolveCommand);
  add(&mlcp::cli::addTableCommand);
  add(&mlcp::cli::addTraceCommand);
  add(&mlcp::cli::addRunCommand);
  add(&mlcp::cli::addStabilityCommand);
  add(&mlcp::cli::addDiffCommand);
  add(&mlcp::cli::addSweepCommand);
  add(&mlcp::cli::addChartCommand);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    // One line, the value echoed short: an option's text can be anything.
    std::cerr << "mlcp: " << mlcp::io::capped(e.what(), 200) << " (see --help)\n";
    return mlcp::cli::kInvalidInput;
  }
  // An engine that cannot express a scene's feature may say so at any step (ODE meets a pair
  // of shapes it has no collider for only when they come close): exit 2 as for bad input.
  try {
    for (auto& [cmd, run] : commands)
      if (cmd->parsed()) return run();
  } catch (const mlcp::scene::Unsupported& e) {
    std::cerr << "mlcp: " << e.what() << "\n";
    return mlcp::cli::kInvalidInput;
  }
  return mlcp::cli::kInvalidInput;
}
