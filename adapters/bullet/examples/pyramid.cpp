// bullet_pyramid: a scene file (default: the 55-box pyramid) in a stock btDiscreteDynamicsWorld,
// with the constraint solver swapped in by one call, world.setConstraintSolver(&solver).
//
//   bullet_pyramid --solver dantzig --steps 300
//   bullet_pyramid --scene scenes/stack_10.json --solver si     (Bullet's stock solver)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <memory>

#include "mlcp/bullet/constraint_solver.hpp"
#include "mlcp/bullet/scene_loader.hpp"
#include "mlcp/registry.hpp"

namespace {

// Height along -gravity of the highest dynamic body, m.
double topHeight(const btDiscreteDynamicsWorld& world, const std::vector<btRigidBody*>& bodies) {
  const btVector3 up =
      world.getGravity().fuzzyZero() ? btVector3(0, 0, 1) : -world.getGravity().normalized();
  double top = -BT_LARGE_FLOAT;
  for (const btRigidBody* b : bodies)
    if (b->getInvMass() > 0) top = std::max(top, double(b->getCenterOfMassPosition().dot(up)));
  return top;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"A scene file in a stock Bullet world; swap the constraint solver by name."};
  std::string file = MLCP_SCENES_DIR "/pyramid_55.json", solverName;
  int steps = 0, every = 50;
  mlcp::bullet::Settings settings;
  app.add_option("--scene", file, "mlcp-scene/1 file")->capture_default_str();
  app.add_option("--solver", solverName,
                 "si (Bullet's stock btSequentialImpulseConstraintSolver) or one of: " +
                     mlcp::solverNames() + " (default: the scene's)");
  app.add_option("--steps", steps, "steps of the scene's time step (default: the scene's)");
  app.add_option("--every", every, "print statistics every this many steps")->capture_default_str();
  app.add_option("--tolerance", settings.options.tolerance,
                 "core solver tolerance (default: the scene's)");
  app.add_option("--max-iterations", settings.options.maxIterations,
                 "core solver iterations (default: the scene's)");
  app.add_option("--fallback", settings.fallback, "fallback core solver, '' for none")
      ->capture_default_str();
  app.add_option("--accept", settings.acceptResidual, "largest accepted scaled residual")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::unique_ptr<mlcp::bullet::BulletScene> built;
  std::unique_ptr<btConstraintSolver> solver;
  mlcp::bullet::ConstraintSolver* ours = nullptr;
  double h = 0;
  try {
    const mlcp::scene::Scene scene = mlcp::scene::loadScene(file);
    const mlcp::scene::RunSettings run = mlcp::scene::RunSettings::fromScene(scene);
    if (solverName.empty()) solverName = run.solver;
    if (steps <= 0) steps = scene.settings.steps;
    if (!app.count("--tolerance")) settings.options.tolerance = run.tolerance;
    if (!app.count("--max-iterations")) settings.options.maxIterations = run.iterations;
    settings.engineIterations = false;  // the scene's limit and tolerance, as `mlcp run`
    settings.warmStart = run.warmStart;
    h = scene.settings.timeStep;

    built = mlcp::bullet::buildWorld(scene, run);
    if (solverName == "si") {
      solver = std::make_unique<btSequentialImpulseConstraintSolver>();
    } else {
      settings.solver = solverName;
      auto drop = std::make_unique<mlcp::bullet::ConstraintSolver>(settings);  // throws if unknown
      ours = drop.get();
      solver = std::move(drop);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bullet_pyramid: %s\n", e.what());
    return 2;
  }
  btDiscreteDynamicsWorld& world = built->world();
  world.setConstraintSolver(solver.get());  // the one-line swap

  const double topStart = topHeight(world, built->bodies());
  for (int s = 1; s <= steps; ++s) {
    world.stepSimulation(h, 0, h);
    if (ours && (s % every == 0 || s == steps)) {
      const mlcp::bullet::StepStats& st = ours->lastStep();
      std::printf(
          "step %4d: islands %d rows %d iterations %d residual %.2e status %s "
          "%.3f ms fallbacks %d\n",
          s, st.islands, st.rows, st.iterations, st.residual, mlcp::toString(st.status),
          st.seconds * 1e3, st.fallbacks);
      if (!st.message.empty()) std::printf("  rejected: %s\n", st.message.c_str());
    }
  }
  std::printf("top body: height %.4f m (started at %.4f m)\n", topHeight(world, built->bodies()),
              topStart);
  if (ours) {
    const mlcp::bullet::StepStats& t = ours->totals();
    std::printf(
        "totals over %d steps: %.3f ms per step, worst residual %.2e, fallbacks %d, "
        "failures %d\n",
        steps, t.seconds * 1e3 / steps, t.residual, t.fallbacks, t.failures);
  }
  return 0;
}
