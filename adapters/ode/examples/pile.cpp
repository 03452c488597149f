// ode_pile: a scene file (default: 216 frictionless spheres piled in a box) in an ODE world,
// stepped by mlcp::ode::Stepper in place of dWorldStep: `stepper.step(world, h)`.
//
//   ode_pile --solver dantzig --steps 200
//   ode_pile --scene scenes/pyramid_15.json --solver dWorldStep     (ODE's stock step)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "mlcp/ode/scene_loader.hpp"
#include "mlcp/ode/stepper.hpp"
#include "mlcp/solver.hpp"

namespace {

struct Args {
  std::string file = MLCP_SCENES_DIR "/sphere_pit.json", solverName;
  int steps = 0, every = 50;
  mlcp::ode::Settings options;
};

void addOptions(CLI::App& app, Args& a) {
  app.add_option("--scene", a.file, "mlcp-scene/1 file")->capture_default_str();
  app.add_option("--solver", a.solverName,
                 "dWorldStep (or ode-world) and dWorldQuickStep (or ode-quick) for ODE's stock "
                 "steps, or one of: " +
                     mlcp::ode::Stepper::knownSolvers() + " (default: the scene's)");
  app.add_option("--steps", a.steps, "steps of the scene's time step (default: the scene's)");
  app.add_option("--every", a.every, "print statistics every this many steps")
      ->capture_default_str();
  app.add_option("--tolerance", a.options.options.tolerance,
                 "core solver tolerance (default: the scene's)");
  app.add_option("--max-iterations", a.options.options.maxIterations,
                 "core solver iterations (default: the scene's)");
  app.add_option("--fallback", a.options.fallback, "fallback core solver, '' for none")
      ->capture_default_str();
  app.add_option("--accept", a.options.acceptResidual, "largest accepted scaled residual")
      ->capture_default_str();
}

// The scene's world and what steps it.
struct Pile {
  std::unique_ptr<mlcp::ode::OdeScene> built;
  std::unique_ptr<mlcp::ode::Stepper> stepper;  // null: ODE's own step
  bool quick = false;
  double h = 0;
};

// Fills what the command line left to the scene; throws for a bad scene or solver name.
Pile buildPile(const CLI::App& app, Args& a) {
  const mlcp::scene::Scene scene = mlcp::scene::loadScene(a.file);
  const mlcp::scene::RunSettings run = mlcp::scene::RunSettings::fromScene(scene);
  if (a.solverName.empty()) a.solverName = run.solver;
  if (a.steps <= 0) a.steps = scene.settings.steps;
  if (!app.count("--tolerance")) a.options.options.tolerance = run.tolerance;
  if (!app.count("--max-iterations")) a.options.options.maxIterations = run.iterations;
  a.options.engineIterations = false;  // the scene's limit and tolerance, as `mlcp run`
  a.options.warmStart = run.warmStart;
  Pile pile;
  pile.h = scene.settings.timeStep;
  pile.built = mlcp::ode::buildWorld(scene, run);
  pile.quick = a.solverName == "dWorldQuickStep" || a.solverName == "ode-quick";
  if (!pile.quick && a.solverName != "dWorldStep" && a.solverName != "ode-world")
    pile.stepper = std::make_unique<mlcp::ode::Stepper>(a.solverName, a.options);  // throws
  return pile;
}

// One step; returns its time (s).
double step(Pile& pile) {
  const dWorldID world = pile.built->world();
  pile.built->collide();
  const double t0 = mlcp::nowSeconds();
  if (pile.stepper)
    pile.stepper->step(world, pile.h);  // in place of dWorldStep(world, h)
  else if (pile.quick)
    dWorldQuickStep(world, pile.h);
  else
    dWorldStep(world, pile.h);
  const double seconds = mlcp::nowSeconds() - t0;
  pile.built->clearContacts();
  return seconds;
}

void printStepperStep(int s, int contacts, const mlcp::ode::StepStats& st, double stepSeconds) {
  mlcp::Status worst = mlcp::Status::Converged;
  for (const mlcp::ode::IslandStats& is : st.islands)
    if (is.rows > 0) worst = std::max(worst, is.status);
  std::printf(
      "step %4d: contacts %d islands %zu rows %d iterations %d residual %.2e status %s "
      "step %.3f ms fallbacks %d choice %s\n",
      s, contacts, st.islands.size(), st.rows(), st.maxIterations(), st.maxResidual(),
      mlcp::toString(worst), stepSeconds * 1e3, st.fallbacks(), st.choices().toString().c_str());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"A scene file in an ODE world; swap dWorldStep for mlcp::ode::Stepper by name."};
  Args args;
  addOptions(app, args);
  CLI11_PARSE(app, argc, argv);

  Pile pile;
  try {
    pile = buildPile(app, args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ode_pile: %s\n", e.what());
    return 2;
  }

  double seconds = 0, worstResidual = 0;
  int fallbacks = 0;
  for (int s = 1; s <= args.steps; ++s) {
    const double stepSeconds = step(pile);
    seconds += stepSeconds;
    const bool print = s % args.every == 0 || s == args.steps;
    if (!pile.stepper) {
      if (print)
        std::printf("step %4d: contacts %d step %.3f ms\n", s, pile.built->contacts(),
                    stepSeconds * 1e3);
      continue;
    }
    const mlcp::ode::StepStats& st = pile.stepper->lastStep();
    worstResidual = std::max(worstResidual, st.maxResidual());
    fallbacks += st.fallbacks();
    if (print) printStepperStep(s, pile.built->contacts(), st, stepSeconds);
  }
  std::printf("totals over %d steps: %.3f ms per step", args.steps, seconds * 1e3 / args.steps);
  if (pile.stepper) std::printf(", worst residual %.2e, fallbacks %d", worstResidual, fallbacks);
  std::printf("\n");
  return 0;
}
