// Core solvers side by side: every registered solver among pgs, dantzig and lemke on the same
// dense SPD boxed problems (n = 10 .. 1000) and one sparse block-banded problem (n = 1002).
// Then box pyramids of 15 and 55 boxes (tests/common/contact_scenes.hpp) as engines hand them
// over: per iteration one time step (perturb b, assemble A sparse from the rows, solve warm
// from the previous step's answer), for dantzig and newton, cold and warm, and pgs for
// reference at a residual target of 1e-6.
// The residual of each answer (mlcp::residual, checked independently) is a counter; so are
// the solver's iterations (sweeps or pivots) and whether it converged. Compare times within
// one run: the machines are noisy.
//
// Captured engine islands (not in the repository): MLCP_BENCH_ISLANDS=base1,base2,... names
// problems saved as base.json (mlcp-problem/1) with their warm start in base.start.json
// (mlcp::io::readVectorJson); each is solved by dantzig and newton cold and warm, with
// iterations (pivots or Newton steps) and the residual as counters.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <random>
#include <sstream>

#include "../common/contact_scenes.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/solvers/pgs.hpp"

namespace {

using namespace mlcp;

// Boxed SPD problem with a random mix of standard, finite-box and equality rows.
Problem denseSpd(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  DenseMatrix B(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) B(i, j) = u(rng);
  DenseMatrix A = B * B.transpose() + 0.1 * n * DenseMatrix::Identity(n, n);
  Vector b(n);
  for (int i = 0; i < n; ++i) b[i] = n * u(rng);
  Problem p(std::move(A), b);
  for (int i = 0; i < n; ++i) {
    if (i % 5 == 0) {
      p.lo[i] = -kInf;
    } else if (i % 5 == 1) {
      p.lo[i] = -1;
      p.hi[i] = 1;
    }
  }
  return p;
}

// Block-tridiagonal SPD (a chain of bodies with 3-row contacts): 334 blocks of 3, n = 1002.
Problem sparseBanded(unsigned seed) {
  const int blocks = 334, n = 3 * blocks;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < blocks; ++k)
    for (int i = 0; i < 3; ++i) {
      const int r = 3 * k + i;
      t.emplace_back(r, r, 4.0);
      for (int j = 0; j < 3; ++j) {
        if (k + 1 < blocks) {
          const double v = 0.4 * u(rng);
          t.emplace_back(r, 3 * (k + 1) + j, v);
          t.emplace_back(3 * (k + 1) + j, r, v);
        }
      }
    }
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  Vector b(n);
  for (int i = 0; i < n; ++i) b[i] = u(rng);
  Problem p(std::move(A), b);
  for (int i = 0; i < n; i += 3) {
    p.lo[i + 1] = p.lo[i + 2] = -0.5;
    p.hi[i + 1] = p.hi[i + 2] = 0.5;
  }
  return p;
}

void run(benchmark::State& state, const std::string& name, const Problem& p) {
  std::unique_ptr<Solver> s = makeSolver(name);
  s->options().maxIterations = 20000;
  Vector x;
  Result r;
  for (auto _ : state) {
    x.resize(0);  // cold start every time
    r = s->solve(p, x);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["n"] = p.size();
  state.counters["residual"] = residual(p, x);
  state.counters["iterations"] = r.iterations;
  state.counters["converged"] = r.converged() ? 1 : 0;
}

void registerAll() {
  static std::vector<Problem> problems;  // owned for the program's lifetime
  const std::vector<int> sizes = {10, 50, 100, 200, 500, 1000};
  problems.reserve(sizes.size() + 1);
  for (int n : sizes) problems.push_back(denseSpd(n, 1000u + n));
  problems.push_back(sparseBanded(7));
  for (const char* name : {"pgs", "dantzig", "newton", "lemke"}) {
    if (!makeSolver(name)) continue;  // not built into this library
    for (size_t k = 0; k < problems.size(); ++k) {
      const Problem* p = &problems[k];
      const std::string label = std::string(name) +
                                (p->isSparse() ? "/sparse_banded/" : "/dense_spd/") +
                                std::to_string(p->size());
      // Lemke's dense tableau beyond n = 500 takes seconds per solve: skip it.
      if (std::string(name) == "lemke" && p->size() > 500) continue;
      benchmark::RegisterBenchmark(label.c_str(), [p, name](benchmark::State& st) {
        run(st, name, *p);
      })->Unit(benchmark::kMillisecond);
    }
  }
}

// One time step per iteration: next b, assembly, solve (warm unless cold) by the named solver
// (pgs at tolerance 1e-6, the others at their default).
void pyramidSteps(benchmark::State& state, int levels, const std::string& name, bool warm) {
  test::PyramidSpec spec;
  spec.levels = levels;
  test::BoxPyramid pyramid(spec);
  std::unique_ptr<Solver> solver = makeSolver(name);
  if (name == "pgs") {
    solver->options().tolerance = 1e-6;
    solver->options().maxIterations = 5000;
  }
  // The previous answer comes from a solve to the default tolerance of the dense path.
  Vector x;
  makeSolver("dantzig")->solve(pyramid.rows().assemble(true), x);
  Problem p;
  Result r;
  double worst = 0;
  int converged = 0, steps = 0;
  for (auto _ : state) {
    pyramid.nextStep(1e-4);
    p = pyramid.rows().assemble(true);
    Vector y;
    r = warm ? solver->solveWithGuess(p, x, y) : solver->solve(p, y);
    x = y;
    worst = std::max(worst, residual(p, y));
    converged += r.converged();
    ++steps;
  }
  state.counters["n"] = p.size();
  state.counters["worst_residual"] = worst;
  state.counters["converged_fraction"] = steps ? double(converged) / steps : 0.0;
  state.counters["iterations"] = r.iterations;
}

void registerPyramids() {
  for (int levels : {5, 10}) {
    const std::string boxes = std::to_string(levels * (levels + 1) / 2);
    for (const char* name : {"dantzig", "newton", "pgs"})
      for (bool warm : {false, true}) {
        const std::string label =
            std::string(name) + "/pyramid" + boxes + (warm ? "/warm" : "/cold");
        auto* b = benchmark::RegisterBenchmark(
            label.c_str(), [=](benchmark::State& st) { pyramidSteps(st, levels, name, warm); });
        b->Unit(benchmark::kMillisecond);
        if (levels == 10) b->Iterations(3);
      }
  }
}

void islandSolve(benchmark::State& state, const Problem& p, const Vector& start,
                 const std::string& name, bool warm) {
  std::unique_ptr<Solver> solver = makeSolver(name);
  Result r;
  Vector x;
  for (auto _ : state) {
    r = warm ? solver->solveWithGuess(p, start, x) : solver->solve(p, x);
  }
  state.counters["n"] = p.size();
  state.counters["residual"] = residual(p, x);
  state.counters["converged"] = r.converged();
  state.counters["iterations"] = r.iterations;
}

void registerIslands() {
  const char* list = std::getenv("MLCP_BENCH_ISLANDS");
  if (!list) return;
  std::stringstream names(list);
  std::string base;
  while (std::getline(names, base, ',')) {
    if (base.empty()) continue;
    const Problem p = io::readProblemJson(base + ".json");
    const Vector start = io::readVectorJson(base + ".start.json");
    for (const char* name : {"dantzig", "newton"})
      for (bool warm : {false, true}) {
        const std::string label = std::string(name) + "/" + base + (warm ? "/warm" : "/cold");
        benchmark::RegisterBenchmark(label.c_str(), [=](benchmark::State& st) {
          islandSolve(st, p, start, name, warm);
        })->Unit(benchmark::kMillisecond);
      }
  }
}

}  // namespace

int main(int argc, char** argv) {
  registerAll();
  registerPyramids();
  registerIslands();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
