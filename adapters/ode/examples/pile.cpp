// ode_pile: a scene file (default: 216 frictionless spheres piled in a box) in an ODE world,
// stepped by mlcp::ode::Stepper in place of dWorldStep: `stepper.step(world, h)`.
//
//   ode_pile --solver dantzig --steps 200
//   ode_pile --scene scenes/pyramid_15.json --solver dWorldStep     (ODE's stock step)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <memory>

#include "mlcp/ode/scene_loader.hpp"
#include "mlcp/ode/stepper.hpp"
#include "mlcp/solver.hpp"

int main(int argc, char** argv) {
  CLI::App app{"A scene file in an ODE world; swap dWorldStep for mlcp::ode::Stepper by name."};
  std::string file = MLCP_SCENES_DIR "/sphere_pit.json", solverName;
  int steps = 0, every = 50;
  mlcp::ode::Settings options;
  app.add_option("--scene", file, "mlcp-scene/1 file")->capture_default_str();
  app.add_option("--solver", solverName,
                 "dWorldStep (or ode-world) and dWorldQuickStep (or ode-quick) for ODE's stock "
                 "steps, or one of: " +
                     mlcp::ode::Stepper::knownSolvers() + " (default: the scene's)");
  app.add_option("--steps", steps, "steps of the scene's time step (default: the scene's)");
  app.add_option("--every", every, "print statistics every this many steps")->capture_default_str();
  app.add_option("--tolerance", options.options.tolerance,
                 "core solver tolerance (default: the scene's)");
  app.add_option("--max-iterations", options.options.maxIterations,
                 "core solver iterations (default: the scene's)");
  app.add_option("--fallback", options.fallback, "fallback core solver, '' for none")
      ->capture_default_str();
  app.add_option("--accept", options.acceptResidual, "largest accepted scaled residual")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::unique_ptr<mlcp::ode::OdeScene> built;
  std::unique_ptr<mlcp::ode::Stepper> stepper;  // null: ODE's own step
  bool quick = false;
  double h = 0;
  try {
    const mlcp::scene::Scene scene = mlcp::scene::loadScene(file);
    const mlcp::scene::RunSettings run = mlcp::scene::RunSettings::fromScene(scene);
    if (solverName.empty()) solverName = run.solver;
    if (steps <= 0) steps = scene.settings.steps;
    if (!app.count("--tolerance")) options.options.tolerance = run.tolerance;
    if (!app.count("--max-iterations")) options.options.maxIterations = run.iterations;
    options.engineIterations = false;  // the scene's limit and tolerance, as `mlcp run`
    options.warmStart = run.warmStart;
    h = scene.settings.timeStep;

    built = mlcp::ode::buildWorld(scene, run);
    quick = solverName == "dWorldQuickStep" || solverName == "ode-quick";
    if (!quick && solverName != "dWorldStep" && solverName != "ode-world")
      stepper = std::make_unique<mlcp::ode::Stepper>(solverName, options);  // throws if unknown
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ode_pile: %s\n", e.what());
    return 2;
  }
  const dWorldID world = built->world();

  double seconds = 0, worstResidual = 0;
  int fallbacks = 0;
  for (int s = 1; s <= steps; ++s) {
    built->collide();
    const double t0 = mlcp::nowSeconds();
    if (stepper)
      stepper->step(world, h);  // in place of dWorldStep(world, h)
    else if (quick)
      dWorldQuickStep(world, h);
    else
      dWorldStep(world, h);
    const double stepSeconds = mlcp::nowSeconds() - t0;
    built->clearContacts();
    seconds += stepSeconds;
    const bool print = s % every == 0 || s == steps;
    if (!stepper) {
      if (print)
        std::printf("step %4d: contacts %d step %.3f ms\n", s, built->contacts(),
                    stepSeconds * 1e3);
      continue;
    }
    const mlcp::ode::StepStats& st = stepper->lastStep();
    mlcp::Status worst = mlcp::Status::Converged;
    for (const mlcp::ode::IslandStats& is : st.islands)
      if (is.rows > 0) worst = std::max(worst, is.status);
    worstResidual = std::max(worstResidual, st.maxResidual());
    fallbacks += st.fallbacks();
    if (print)
      std::printf(
          "step %4d: contacts %d islands %zu rows %d iterations %d residual %.2e status %s "
          "step %.3f ms fallbacks %d choice %s\n",
          s, built->contacts(), st.islands.size(), st.rows(), st.maxIterations(), st.maxResidual(),
          mlcp::toString(worst), stepSeconds * 1e3, st.fallbacks(),
          st.choices().toString().c_str());
  }
  std::printf("totals over %d steps: %.3f ms per step", steps, seconds * 1e3 / steps);
  if (stepper) std::printf(", worst residual %.2e, fallbacks %d", worstResidual, fallbacks);
  std::printf("\n");
  return 0;
}
