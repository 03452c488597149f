// bullet_pyramid: a box pyramid falling into place in a stock btDiscreteDynamicsWorld, with the
// constraint solver picked on the command line.
//
//   bullet_pyramid --solver dantzig --boxes 55 --steps 300
//   bullet_pyramid --solver si          (Bullet's stock solver)
#include <CLI/CLI.hpp>
#include <cstdio>

#include "scenes.hpp"

int main(int argc, char** argv) {
  namespace sc = mlcp::bullet::scenes;
  CLI::App app{"A box pyramid in a stock Bullet world; swap the constraint solver by name."};
  std::string solver = "pgs";
  int boxes = 55, steps = 300, every = 50;
  mlcp::bullet::Settings settings;
  app.add_option("--solver", solver, "one of: " + sc::bulletSolverNames())->capture_default_str();
  app.add_option("--boxes", boxes, "pyramid size: 15, 55, 210, ...")->capture_default_str();
  app.add_option("--steps", steps, "steps of 1/60 s")->capture_default_str();
  app.add_option("--every", every, "print statistics every this many steps")->capture_default_str();
  app.add_option("--tolerance", settings.options.tolerance, "core solver tolerance")
      ->capture_default_str();
  app.add_option("--max-iterations", settings.options.maxIterations, "core solver iterations")
      ->capture_default_str();
  app.add_option("--fallback", settings.fallback, "fallback core solver, '' for none")
      ->capture_default_str();
  app.add_option("--accept", settings.acceptResidual, "largest accepted scaled residual")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  sc::World world;
  try {
    world.setSolver(sc::makeBulletSolver(solver, settings));
    sc::pyramid(world, boxes);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bullet_pyramid: %s\n", e.what());
    return 2;
  }
  auto* ours = dynamic_cast<mlcp::bullet::ConstraintSolver*>(world.solver());
  const btRigidBody* top = world.dynamicBodies().back();
  const double topStart = top->getCenterOfMassPosition().y();
  for (int s = 1; s <= steps; ++s) {
    world.step();
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
  std::printf("top box: y %.4f m (started at %.4f m)\n", top->getCenterOfMassPosition().y(),
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
