// ode_pgs_bench: our stepper with "pgs" against dWorldQuickStep at the same sweep count, on box
// pyramids of about 100, 500 and 2000 constraint rows, ratios measured in one run.
//
//     build/bench/ode_pgs_bench [steps] [warm-up steps] [sweeps] [reference sweeps] [base]
//                               (defaults 30, 40, 20, 5000, all three piles; a base 3, 6 or
//                               12 runs that pile only, e.g. under a profiler)
//
// Same problems: a reference pile is stepped by a converged solve (our pgs, up to 5000 sweeps,
// tolerance 1e-9: its residual is printed); before every step the QuickStep pile and the pgs
// pile are set to the reference pile's state (positions, orientations, velocities), so all
// three solve the same contacts from the same state (identical piles; dCollide is
// deterministic). Our pgs warm-starts from its own previous step, which began from the
// reference state too; QuickStep has no warm start. Both run `sweeps` sweeps with SOR factor
// 1.3 (QuickStep's default), no convergence test.
//
// Time: CPU time of this thread in dWorldQuickStep / Stepper::step (islands, rows, solve,
// integration; not collision), median over the timed steps. On a shared machine wall time
// mostly measures the other processes. Ours is also split (wall-clock medians from
// IslandStats): "solve" is RowSolver::solve (RowPgs: validation, packing, sweeps, the residual
// check), "rest" the island's other stages (getInfo1/getInfo2 into rows, right-hand side, warm
// start, impulses and integration) plus the step's own (ODE's island search and arena).
// QuickStep cannot be split from outside.
//
// Accuracy. Ours: the scaled natural-map residual (mlcp::accuracy) of every island's answer,
// worst over the steps. QuickStep's residual cannot be measured from outside: its lambda lives in
// the step's arena and is not returned, and joint feedback gives J^T lambda summed per body,
// which would have to be inverted on rows in QuickStep's internal order. Both methods are
// therefore also compared by the velocity error after the step: max over bodies and components
// of |v - v_ref| (m/s, rad/s) against the converged reference from the same state (g h = 0.098
// m/s for scale). It is the error of the constraint impulses as the bodies feel it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <vector>

#include "mlcp/ode/stepper.hpp"
#include "ode/ode_scenes.hpp"

using namespace mlcp::ode;
using namespace mlcp::ode::test;

namespace {

double cpuNow() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 30;
  const int warmup = argc > 2 ? std::max(0, std::atoi(argv[2])) : 40;
  const int sweeps = argc > 3 ? std::max(1, std::atoi(argv[3])) : 20;
  const int referenceSweeps = argc > 4 ? std::max(1, std::atoi(argv[4])) : 5000;
  const int only = argc > 5 ? std::atoi(argv[5]) : 0;
  const dReal h = 0.01;

  std::printf(
      "| base | rows | sweeps | QuickStep ms | ours pgs ms | pgs / QuickStep | QuickStep max |dv| "
      "| pgs max |dv| | pgs residual | reference residual | ours: solve ms | ours: rest ms "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int base : {3, 6, 12}) {
    if (only > 0 && base != only) continue;
    auto ref = boxPyramid(base), quick = boxPyramid(base), ours = boxPyramid(base);
    dWorldSetQuickStepNumIterations(quick->world, sweeps);
    dWorldSetQuickStepW(quick->world, 1.3);

    StepperOptions tight;
    tight.solver.maxIterations = referenceSweeps;
    tight.solver.checkEvery = 10;
    tight.solver.tolerance = 1e-9;
    tight.solver.relaxation = 1.0;
    tight.fallback = "";
    Stepper reference("pgs", tight);
    StepperOptions fixed;
    fixed.solver.maxIterations = sweeps;
    fixed.solver.relaxation = 1.3;
    fixed.solver.checkEvery = sweeps;
    fixed.solver.tolerance = 0;
    fixed.fallback = "";
    Stepper pgs("pgs", fixed);

    auto stepRef = [&](dWorldID w, dReal dt) { reference.step(w, dt); };
    for (int k = 0; k < warmup; ++k) ref->step(stepRef, h);

    std::vector<double> tQuick, tPgs, tSolve, tRest;
    double dvQuick = 0, dvPgs = 0, resPgs = 0, resRef = 0;
    int rows = 0;
    for (int k = 0; k < steps; ++k) {
      copyState(*ref, *quick);
      copyState(*ref, *ours);
      quick->step(
          [&](dWorldID w, dReal dt) {
            const double t0 = cpuNow();
            dWorldQuickStep(w, dt);
            tQuick.push_back(1e3 * (cpuNow() - t0));
          },
          h);
      ours->step(
          [&](dWorldID w, dReal dt) {
            const double t0 = cpuNow();
            pgs.step(w, dt);
            tPgs.push_back(1e3 * (cpuNow() - t0));
            double solve = 0;
            for (const IslandStats& is : pgs.lastStep().islands) solve += is.solveSeconds;
            tSolve.push_back(1e3 * solve);
            tRest.push_back(1e3 * (pgs.lastStep().seconds - solve));
          },
          h);
      ref->step(stepRef, h);
      dvQuick = std::max(dvQuick, velocityDifference(*quick, *ref));
      dvPgs = std::max(dvPgs, velocityDifference(*ours, *ref));
      resPgs = std::max(resPgs, pgs.lastStep().maxResidual());
      resRef = std::max(resRef, reference.lastStep().maxResidual());
      rows = pgs.lastStep().rows();
    }
    const double q = median(tQuick), p = median(tPgs);
    std::printf(
        "| %d | %d | %d | %.3f | %.3f | %.2fx | %.2e | %.2e | %.2e | %.1e | %.3f | %.3f |\n", base,
        rows, sweeps, q, p, p / q, dvQuick, dvPgs, resPgs, resRef, median(tSolve), median(tRest));
    std::fflush(stdout);
  }
  return 0;
}
