// ODE adapter benchmark: our stepper (pgs, dantzig) against stock dWorldStep and
// dWorldQuickStep on box pyramids of about 100, 500 and 2000 constraint rows, timed side by
// side in one run (median per step), with the residual of every answer measured by the same
// function (mlcp::accuracy on the island's rows).
//
//     build/bench/ode_bench [steps] [warm-up steps]     (defaults 20 and 20)
//
// Same world state for every method: one pile is stepped by our dantzig (the reference
// trajectory); before each step every other method's pile is set to the reference pile's state
// (positions, orientations, velocities), so all methods solve the very same contacts from the
// very same state at every step (the piles are built identically; dCollide is deterministic).
// Methods with a warm start (ours) take it from their own previous step, which started from the
// reference state too. The other methods step only in the last 3 warm-up steps and the timed
// steps. "max |dv| vs dantzig" is the largest difference of any body's linear or angular
// velocity after the step from the reference's, in m/s or rad/s (g h = 0.098 m/s for scale):
// "equal answers" means the same residual level and |dv| far below g h; the steps column
// counts the timed steps with |dv| > 1e-6 (dWorldStep's dxSolveLCP sometimes stops with
// "LCP internal error, s <= 0" on these piles and returns a wrong answer).
//
// "stock dWorldStep residual" is that of ODE's own dxSolveLCP on our assembled rows (the
// "ode-lcp" reference of our dantzig stepper, equal to dWorldStep to round-off; see
// tests/ode/plumbing_test.cpp); its time is excluded from our dantzig's time. The island
// count shows whether the pile is one island. pgs runs QuickStep's iteration count (20) and
// relaxation (1.3) without convergence checks.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "mlcp/ode/stepper.hpp"
#include "mlcp/solver.hpp"
#include "ode/ode_scenes.hpp"

using namespace mlcp::ode;
using namespace mlcp::ode::test;

namespace {

struct Method {
  std::string name;
  std::unique_ptr<Stepper> stepper;  // null: stock
  bool quick = false;
  std::unique_ptr<Scene> scene;
  std::vector<double> times;
  double residual = 0;      // worst over the timed steps
  double velocityDiff = 0;  // worst max |dv| against the reference (our dantzig)
  int differing = 0;        // timed steps with max |dv| > 1e-6
  int rows = 0;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 20;
  const int warmup = argc > 2 ? std::max(3, std::atoi(argv[2])) : 20;
  const dReal h = 0.01;

  std::printf(
      "| pyramid base | rows | islands | method | ms/step | x dWorldStep | worst residual | "
      "max \\|dv\\| vs dantzig (steps) |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (int base : {3, 7, 12}) {
    std::vector<Method> methods;
    auto add = [&](const std::string& name, std::unique_ptr<Stepper> s, bool quick) {
      Method m;
      m.name = name;
      m.stepper = std::move(s);
      m.quick = quick;
      m.scene = boxPyramid(base);
      methods.push_back(std::move(m));
    };
    add("dWorldStep", nullptr, false);
    add("dWorldQuickStep (20 it)", nullptr, true);
    Settings pgs;
    pgs.options.maxIterations = 20;
    pgs.options.relaxation = 1.3;
    pgs.options.checkEvery = 1000000;
    pgs.options.tolerance = 0;
    pgs.engineIterations = false;
    pgs.fallback = "";
    add("ours pgs (20 it, w 1.3, warm)", std::make_unique<Stepper>("pgs", pgs), false);
    Settings dz;
    dz.reference = "ode-lcp";  // stock's residual on the very same problems
    dz.timeBudget = 0;         // the reference runs to its tolerance
    add("ours dantzig (exact)", std::make_unique<Stepper>("dantzig", dz), false);
    Settings nw;
    nw.timeBudget = 0;
    add("ours newton (1e-6)", std::make_unique<Stepper>("newton", nw), false);
    Method& ref = methods[3];
    int islands = 0;

    for (int k = 0; k < warmup + steps; ++k) {
      const bool all = k >= warmup - 3;
      for (Method& m : methods)
        if (&m != &ref && all) copyState(*ref.scene, *m.scene);
      for (Method& m : methods) {
        if (&m != &ref && !all) continue;
        const double t0 = mlcp::nowSeconds();
        m.scene->step(
            [&](dWorldID w, dReal dt) {
              if (m.stepper)
                m.stepper->step(w, dt);
              else if (m.quick)
                dWorldQuickStep(w, dt);
              else
                dWorldStep(w, dt);
            },
            h);
        double t = mlcp::nowSeconds() - t0;
        if (m.stepper)
          for (const IslandStats& st : m.stepper->lastStep().islands) t -= st.referenceSeconds;
        if (k < warmup) continue;
        m.times.push_back(t);
        if (m.stepper) {
          m.residual = std::max(m.residual, m.stepper->lastStep().maxResidual());
          m.rows = m.stepper->lastStep().rows();
          if (&m == &ref) {
            int withRows = 0;
            for (const IslandStats& st : m.stepper->lastStep().islands) {
              if (st.rows == 0) continue;
              ++withRows;
              methods[0].residual = std::max(methods[0].residual, st.referenceResidual);
            }
            islands = std::max(islands, withRows);
          }
        }
      }
      if (k >= warmup)
        for (Method& m : methods) {
          if (&m == &ref) continue;
          const double d = velocityDifference(*m.scene, *ref.scene);
          m.velocityDiff = std::max(m.velocityDiff, d);
          m.differing += d > 1e-6;
        }
    }
    const double stock = median(methods[0].times);
    for (const Method& m : methods) {
      const double t = median(m.times);
      char res[32] = "n/a", dv[64] = "0 (reference)";
      if (m.stepper || (&m == &methods[0])) std::snprintf(res, sizeof res, "%.2e", m.residual);
      if (&m != &ref)
        std::snprintf(dv, sizeof dv, "%.1e (%d of %d > 1e-6)", m.velocityDiff, m.differing, steps);
      std::printf("| %d | %d | %d | %s | %.3f | %.2f | %s | %s |\n", base, ref.rows, islands,
                  m.name.c_str(), 1e3 * t, stock / t, res, dv);
      std::fflush(stdout);
    }
  }
  std::printf(
      "\n(x dWorldStep = dWorldStep's time / this method's time, all on the same state per step; "
      "residual: scaled natural-map residual, mlcp::accuracy; islands: islands with rows)\n");
  return 0;
}
