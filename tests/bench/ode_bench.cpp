// ODE adapter benchmark: our stepper (pgs, dantzig) against stock dWorldStep and
// dWorldQuickStep on box pyramids of about 100, 500 and 2000 constraint rows, timed side by
// side in one run (interleaved step by step, median per step), with the residual of every
// answer measured by the same function (mlcp::accuracy on the island's rows).
//
//     build/bench/ode_bench [steps]     (default 30 timed steps per method and size)
//
// "stock dWorldStep residual" is that of ODE's own dxSolveLCP on our assembled rows (the
// "ode-lcp" method, equal to dWorldStep to round-off; see tests/ode/plumbing_test.cpp).
// pgs runs QuickStep's iteration count (20) and relaxation (1.3) without convergence checks.
#include <algorithm>
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
  double residual = 0;  // worst over the timed steps
  int rows = 0;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 30;
  const dReal h = 0.01;

  std::printf("| pyramid base | rows | method | ms/step | x dWorldStep | worst residual |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (int base : {3, 6, 12}) {
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
    StepperOptions pgs;
    pgs.solver.maxIterations = 20;
    pgs.solver.relaxation = 1.3;
    pgs.solver.checkEvery = 1000000;
    pgs.solver.tolerance = 0;
    pgs.fallback = "";
    add("ours pgs (20 it, w 1.3, warm)", std::make_unique<Stepper>("pgs", pgs), false);
    StepperOptions dz;
    dz.reference = "ode-lcp";  // stock's residual on the very same problems
    add("ours dantzig (exact)", std::make_unique<Stepper>("dantzig", dz), false);

    // Settle every pile with its own method, then time steps interleaved.
    for (int k = 0; k < 40 + steps; ++k) {
      for (Method& m : methods) {
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
        if (k < 40) continue;
        m.times.push_back(mlcp::nowSeconds() - t0);
        if (m.stepper) {
          m.residual = std::max(m.residual, m.stepper->lastStep().maxResidual());
          m.rows = m.stepper->lastStep().rows();
          if (m.name.find("dantzig") != std::string::npos)
            for (const IslandStats& st : m.stepper->lastStep().islands)
              if (st.rows > 0)
                methods[0].residual = std::max(methods[0].residual, st.referenceResidual);
        }
      }
    }
    const double stock = median(methods[0].times);
    for (const Method& m : methods) {
      const double t = median(m.times);
      char res[32] = "n/a";
      if (m.stepper || (&m == &methods[0])) std::snprintf(res, sizeof res, "%.2e", m.residual);
      std::printf("| %d | %d | %s | %.3f | %.2f | %s |\n", base, methods[3].rows, m.name.c_str(),
                  1e3 * t, stock / t, res);
    }
  }
  std::printf(
      "\n(x dWorldStep = dWorldStep's time / this method's time; residual: scaled "
      "natural-map residual, mlcp::accuracy)\n");
  return 0;
}
