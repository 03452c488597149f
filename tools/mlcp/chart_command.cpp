// mlcp chart work-precision SWEEP.csv -o DIR | mlcp chart heatmap STABILITY.csv -o DIR:
// tools/chart.py run by the project's venv Python, every argument passed through.
//
// Where things are: the source folder is baked in at configure time (MLCP_SOURCE_DIR) so that
// a build-tree or installed binary finds tools/chart.py and .venv/bin/python; the environment
// variables MLCP_SOURCE_DIR (another checkout) and MLCP_PYTHON (another interpreter with
// matplotlib) override them.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"

#ifndef MLCP_SOURCE_DIR
#define MLCP_SOURCE_DIR "."
#endif

namespace mlcp::cli {

namespace {

std::string envOr(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

}  // namespace

int runChart(const std::vector<std::string>& passed) {
  const std::string source = envOr("MLCP_SOURCE_DIR", MLCP_SOURCE_DIR);
  const std::string python = envOr("MLCP_PYTHON", source + "/.venv/bin/python");
  const std::string script = source + "/tools/chart.py";
  if (access(script.c_str(), R_OK) != 0) {
    std::cerr << "mlcp chart: " << script
              << " not found (set MLCP_SOURCE_DIR to the mlcp source folder)\n";
    return kNotSolved;
  }
  if (access(python.c_str(), X_OK) != 0) {
    std::cerr << "mlcp chart: no Python at " << python
              << "; run tools/setup.sh to build the venv (or set MLCP_PYTHON to a Python with "
                 "matplotlib)\n";
    return kNotSolved;
  }
  std::vector<std::string> argv{python, script};
  argv.insert(argv.end(), passed.begin(), passed.end());
  std::vector<char*> cargv;
  for (std::string& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  std::cout.flush();
  const pid_t pid = fork();
  if (pid < 0) {
    std::cerr << "mlcp chart: cannot start " << python << "\n";
    return kNotSolved;
  }
  if (pid == 0) {
    execv(python.c_str(), cargv.data());
    std::cerr << "mlcp chart: cannot run " << python << "\n";
    _exit(kNotSolved);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status)) return kNotSolved;
  return WEXITSTATUS(status);  // chart.py: 0 written, 2 bad CSV or arguments
}

Runner addChartCommand(CLI::App& app) {
  auto args = std::make_shared<std::vector<std::string>>();
  CLI::App* cmd = app.add_subcommand(
      "chart",
      "Draw charts with tools/chart.py (venv Python from tools/setup.sh; MLCP_PYTHON and "
      "MLCP_SOURCE_DIR override where they are). Modes: `work-precision SWEEP.csv -o DIR "
      "[--stat mean|median|max]` (one chart per scene from `mlcp sweep`) and `heatmap "
      "STABILITY.csv -o DIR` (from `mlcp stability`); `mlcp chart work-precision --help` for "
      "the script's own help. Exit 0: charts written; 1: no Python or script; 2: bad CSV or "
      "arguments.");
  cmd->prefix_command();  // everything after `chart` goes to the script
  return [cmd, args] {
    *args = cmd->remaining();
    if (args->empty()) {
      std::cerr << "mlcp chart: give a mode: work-precision SWEEP.csv -o DIR, or heatmap "
                   "STABILITY.csv -o DIR\n";
      return static_cast<int>(kInvalidInput);
    }
    return runChart(*args);
  };
}

}  // namespace mlcp::cli
