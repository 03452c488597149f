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
// reference state too (the first timed step from an untimed one at the last warm-up state;
// without it that step is a cold start, and at base 6 it was the pgs' worst residual, 4.4e-2);
// QuickStep has no warm start. Both run `sweeps` sweeps with SOR factor 1.3 (QuickStep's
// default), no convergence test.
//
// Time: CPU time of this thread in dWorldQuickStep / Stepper::step (islands, rows, solve,
// integration; not collision), median over the timed steps. On a shared machine wall time
// mostly measures the other processes. Ours is also split (wall-clock medians from
// IslandStats): "solve" is RowSolver::solve (RowPgs: validation, packing, sweeps, the residual
// check), "rest" the island's other stages (getInfo1/getInfo2 into rows, right-hand side, warm
// start, impulses and integration) plus the step's own (ODE's island search and arena).
// QuickStep cannot be split from outside.
//
// Accuracy, on the very MLCP our stepper builds (Settings::keepProblems: the rows,
// right-hand side, bounds and findex RowPgs received) and by the one function that measures
// every answer (mlcp::accuracy on rows.assemble(), the scaled natural-map residual), worst over
// islands per step, then worst and median over the timed steps:
//   - ours: the applied lambda (recomputed; "recheck" is its largest difference from what
//     IslandStats::residual reported, the sanity check of the kept problem);
//   - QuickStep: its lambda recovered from joint feedback (tests/ode/feedback_lambda.hpp).
//     ODE does not return QuickStep's multipliers, but stage 4b writes f1 t1 f2 t2 = J^T lambda
//     per joint with the J copied before the SOR scales it, lambda in force units as ours (its
//     rhs and cfm are dxStepIsland's: c/h - J (M^-1 f_ext + v/h), cfm/h). A fourth pile, set
//     to the same state, is stepped by dWorldQuickStep with a feedback on every contact and
//     ODE's random generator reset to the seed the timed QuickStep started from (QuickStep
//     shuffles its rows with dRandInt every 8th sweep): its step must end bitwise in the timed
//     pile's state, or the bench stops. Each of our contact joints has a twin there, the
//     contact with the same bodies and position (dCollide is deterministic; the normal and
//     depth are compared too, or the bench stops); per joint, lambda is the least-squares
//     solution of J_k^T lambda = the twin's feedback on our rows of that joint ("fit": the
//     largest scaled misfit, ~1e-16 when exact).
// The velocity error after the step is kept too: max over bodies and components of
// |v - v_ref| (m/s, rad/s) against the converged reference from the same state (g h = 0.098
// m/s for scale), the error of the constraint impulses as the bodies feel it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "mlcp/cpu.hpp"
#include "mlcp/ode/stepper.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/row_pgs.hpp"
#include "ode/feedback_lambda.hpp"
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

double worst(const std::vector<double>& v) {
  double w = 0;
  for (double x : v) w = std::max(w, x);
  return w;
}

[[noreturn]] void fail(const char* what, int base, int step) {
  std::fprintf(stderr, "ode_pgs_bench: base %d, step %d: %s\n", base, step, what);
  std::exit(1);
}

struct Residuals {
  double quick = 0, ours = 0;  // worst over the step's islands
  double recheck = 0, fit = 0;
};

// QuickStep's lambda (from `probe`'s contact feedback) and ours on every island problem our
// stepper kept this step (see the header comment).
Residuals residuals(const Stepper& pgs, const Scene& ours, const Scene& probe, int base, int step) {
  const auto &oc = ours.contactRecords(), &pc = probe.contactRecords();
  if (oc.size() != pc.size()) fail("the piles have different contacts", base, step);
  // Twins by bodies and position (the creation order follows the space's geom list, which
  // changes with the order bodies were moved in); normal and depth must then agree too.
  using Key = std::tuple<int, int, double, double, double>;
  auto keyOf = [](const Scene::ContactRecord& c) {
    return Key(c.body0, c.body1, c.geom.pos[0], c.geom.pos[1], c.geom.pos[2]);
  };
  std::map<Key, std::size_t> probeContact;
  for (std::size_t k = 0; k < pc.size(); ++k) probeContact[keyOf(pc[k])] = k;
  if (probeContact.size() != pc.size()) fail("two contacts at one place", base, step);
  // Our contact joint -> its twin in `probe`.
  std::unordered_map<dJointID, std::size_t> twinOf;
  for (const Scene::ContactRecord& c : oc) {
    const auto it = probeContact.find(keyOf(c));
    if (it == probeContact.end()) fail("a contact without a twin in the other pile", base, step);
    const dContactGeom& b = pc[it->second].geom;
    bool same = c.geom.depth == b.depth;
    for (int d = 0; d < 3; ++d) same = same && c.geom.normal[d] == b.normal[d];
    if (!same) fail("twin contacts with different normals or depths", base, step);
    twinOf[c.joint] = it->second;
  }
  Residuals r;
  for (const IslandProblem& p : pgs.lastProblems()) {
    mlcp::Vector quick = mlcp::Vector::Constant(p.rows.size(), NAN);
    for (const IslandProblem::JointRange& j : p.joints) {
      const auto it = twinOf.find(j.joint);
      if (it == twinOf.end()) fail("a joint that is not a recorded contact", base, step);
      r.fit = std::max(
          r.fit, lambdaFromFeedback(p.rows, j.first, j.count, *pc[it->second].feedback, quick));
    }
    if (!quick.allFinite()) fail("rows without a recovered lambda", base, step);
    const mlcp::Problem problem = p.rows.assemble(true);
    const double ourResidual = mlcp::accuracy(problem, p.lambda).residual;
    r.ours = std::max(r.ours, ourResidual);
    r.quick = std::max(r.quick, mlcp::accuracy(problem, quick).residual);
    r.recheck =
        std::max(r.recheck, std::abs(ourResidual - pgs.lastStep().islands.at(p.island).residual));
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 30;
  const int warmup = argc > 2 ? std::max(0, std::atoi(argv[2])) : 40;
  const int sweeps = argc > 3 ? std::max(1, std::atoi(argv[3])) : 20;
  const int referenceSweeps = argc > 4 ? std::max(1, std::atoi(argv[4])) : 5000;
  const int only = argc > 5 ? std::atoi(argv[5]) : 0;
  const dReal h = 0.01;

  // Which machine code RowPgs runs (MLCP_CPU_PATH=baseline forces the baseline).
  std::printf("RowPgs cpu path: %s\n", mlcp::toString(mlcp::cpuPath()));
  std::printf(
      "| base | rows | sweeps | QuickStep ms | ours pgs ms | pgs / QuickStep | QuickStep max |dv| "
      "| pgs max |dv| | QuickStep residual worst (median) | pgs residual worst (median) "
      "| reference residual | ours: solve ms | ours: rest ms | fit | recheck |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int base : {3, 6, 12}) {
    if (only > 0 && base != only) continue;
    auto ref = boxPyramid(base), quick = boxPyramid(base), probe = boxPyramid(base),
         ours = boxPyramid(base);
    for (Scene* s : {quick.get(), probe.get()}) {
      dWorldSetQuickStepNumIterations(s->world, sweeps);
      dWorldSetQuickStepW(s->world, 1.3);
    }
    probe->recordContacts = probe->contactFeedback = true;
    ours->recordContacts = true;

    Settings tight;
    tight.options.maxIterations = referenceSweeps;
    tight.options.checkEvery = 10;
    tight.options.tolerance = 1e-9;
    tight.options.relaxation = 1.0;
    tight.engineIterations = false;
    tight.fallback = "";
    Stepper reference("pgs", tight);
    // keepProblems: swapped out, not copied: no measurable cost (stepper.hpp).
    Stepper pgs("pgs", fixedSweepPgs(sweeps, true));

    auto stepRef = [&](dWorldID w, dReal dt) { reference.step(w, dt); };
    for (int k = 0; k < warmup; ++k) {
      if (k == warmup - 1) {
        // Our pgs steps once, untimed, from the state before the first timed one, so that the
        // first timed step is warm-started like the others (from the last step's answer). The
        // QuickStep piles step too: a body moved by a step goes to the front of its space's
        // geom list, and that order decides dCollide's argument order, hence the contacts.
        for (Scene* s : {quick.get(), probe.get(), ours.get()}) copyState(*ref, *s);
        for (Scene* s : {quick.get(), probe.get()})
          s->step([](dWorldID w, dReal dt) { dWorldQuickStep(w, dt); }, h);
        ours->step([&](dWorldID w, dReal dt) { pgs.step(w, dt); }, h);
      }
      ref->step(stepRef, h);
    }

    std::vector<double> tQuick, tPgs, tSolve, tRest, resQuick, resPgs;
    double dvQuick = 0, dvPgs = 0, resRef = 0, fit = 0, recheck = 0;
    int rows = 0;
    for (int k = 0; k < steps; ++k) {
      copyState(*ref, *quick);
      copyState(*ref, *probe);
      copyState(*ref, *ours);
      const unsigned long seed = dRandGetSeed();
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
      // The measurement after both timed steps, which thus run back to back as before it.
      dRandSetSeed(seed);
      probe->step([](dWorldID w, dReal dt) { dWorldQuickStep(w, dt); }, h);
      if (quick->state() != probe->state())
        fail("QuickStep with feedback did not repeat the timed step", base, k);
      const Residuals r = residuals(pgs, *ours, *probe, base, k);
      resQuick.push_back(r.quick);
      resPgs.push_back(r.ours);
      fit = std::max(fit, r.fit);
      recheck = std::max(recheck, r.recheck);
      ref->step(stepRef, h);
      dvQuick = std::max(dvQuick, velocityDifference(*quick, *ref));
      dvPgs = std::max(dvPgs, velocityDifference(*ours, *ref));
      resRef = std::max(resRef, reference.lastStep().maxResidual());
      rows = pgs.lastStep().rows();
    }
    const double q = median(tQuick), p = median(tPgs);
    std::printf(
        "| %d | %d | %d | %.3f | %.3f | %.2fx | %.2e | %.2e | %.2e (%.2e) | %.2e (%.2e) | %.1e "
        "| %.3f | %.3f | %.0e | %.0e |\n",
        base, rows, sweeps, q, p, p / q, dvQuick, dvPgs, worst(resQuick), median(resQuick),
        worst(resPgs), median(resPgs), resRef, median(tSolve), median(tRest), fit, recheck);
    std::fflush(stdout);
  }
  return 0;
}
