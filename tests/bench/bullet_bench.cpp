// bullet_bench: per-step constraint-solver time and reached residual of our solvers (through the
// drop-in mlcp::bullet::ConstraintSolver) against Bullet's SI and the stock btMLCPSolver with
// its PGS, Dantzig and Lemke, on box pyramids of 15, 55 and 210 boxes. All ratios are measured
// in one run. A plain program printing a table and a CSV (Google Benchmark's fixed-time loops
// do not fit minute-long stock steps).
//
// Method: every configuration gets a fresh pyramid, settles it with SI for `warmup` steps (the
// same states for all), then switches to its solver and times `steps` steps. Time is the wall
// time of btConstraintSolver::solveGroup (Bullet's row setup, the solve and the write-back),
// minus the time spent measuring residuals for this table; "cpu ms" is the same in this thread's
// CPU time (on a shared machine wall time also counts the other processes). Residuals are the
// scaled natural-map residual (mlcp::accuracy) of each step's answer, worst over the timed
// steps, on the problem the stock btMLCPSolver assembles: our solvers use CfmModel::StockMlcp
// for that reason.
// globalCfm is 1e-5 (what Bullet's demos use with direct solvers; with 0 a box face's four
// contact points make A singular). A configuration whose step is predicted (n^3 from the
// previous size for pivoting methods) or measured to take more than 1 s is skipped.
// --settle N runs N untimed steps with the configuration's own solver between the switch and
// the timed steps: by default (0) the timed steps are the pyramid moving from SI's approximate
// answers to the solver's own (exact solvers move it for ~40 steps, which no warm start helps);
// with --settle 60 they are the pyramid at rest under that solver, the steady state of a demo.
// docs/benchmarks.md reports both.
//
//   bullet_bench [--steps N] [--warmup N] [--settle N] [--sizes 15,55,210] [--csv file]
//                [--only "ours dantzig,MLCP-Dantzig"]   (labels containing one of the parts)
//   bullet_bench --pgs-vs-si [--sweeps 10,50] [--steps N]   (ours pgs / SI, stepped alternately)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>

#include "mlcp/cpu.hpp"
#include "mlcp/solver.hpp"
#include "mlcp/solvers/row_pgs.hpp"
#include "scenes.hpp"

namespace {

namespace sc = mlcp::bullet::scenes;

// Times solveGroup of the solver it wraps.
class Timed : public btConstraintSolver {
 public:
  explicit Timed(std::unique_ptr<btConstraintSolver> inner) : inner_(std::move(inner)) {}
  void prepareSolve(int nb, int nm) override { inner_->prepareSolve(nb, nm); }
  btScalar solveGroup(btCollisionObject** b, int nb, btPersistentManifold** m, int nm,
                      btTypedConstraint** c, int nc, const btContactSolverInfo& info,
                      btIDebugDraw* dd, btDispatcher* d) override {
    const double t0 = mlcp::nowSeconds(), c0 = cpuNow();
    const btScalar r = inner_->solveGroup(b, nb, m, nm, c, nc, info, dd, d);
    seconds += mlcp::nowSeconds() - t0;
    cpuSeconds += cpuNow() - c0;
    return r;
  }
  void allSolved(const btContactSolverInfo& info, btIDebugDraw* dd) override {
    inner_->allSolved(info, dd);
  }
  void reset() override { inner_->reset(); }
  btConstraintSolverType getSolverType() const override { return inner_->getSolverType(); }
  btConstraintSolver* inner() { return inner_.get(); }
  double seconds = 0;
  double cpuSeconds = 0;  // this thread's CPU time (robust to other processes' load)
  static double cpuNow() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
  }

 private:
  std::unique_ptr<btConstraintSolver> inner_;
};

struct Config {
  std::string label;  // table name
  std::string name;   // makeBulletSolver name
  bool pivoting;      // time grows like n^3 (skip prediction)
};

struct Row {
  double ms = NAN, residual = NAN;
  int rows = 0, fallbacks = 0, iterations = 0;
  double assembleMs = NAN, solveMs = NAN;  // solveMs: our stages 2-7 (SI: its iterations)
  double cpuMs = NAN;  // as ms, in this thread's CPU time (robust to other processes' load)
  std::string note;
};

Row run(const Config& cfg, int boxes, int warmup, int settle, int steps) {
  sc::World w;
  w.info().m_globalCfm = 1e-5;
  sc::pyramid(w, boxes);
  w.step(warmup);  // stock SI settles the pyramid: every configuration starts from this state

  mlcp::bullet::Settings s;
  s.cfm = mlcp::bullet::CfmModel::StockMlcp;
  if (cfg.name == "pgs") {
    // Sequential-impulse-like: Bullet's 10 sweeps, residual checked once, always accepted.
    s.engineIterations = true;
    s.acceptResidual = INFINITY;
    s.fallback = "";
  } else {
    s.timeBudget = 0;  // our exact solvers run to their tolerance, as the stock pivoting does
  }
  w.setSolver(std::make_unique<Timed>(sc::makeBulletSolver(cfg.name, s)));
  auto* timed = static_cast<Timed*>(w.solver());
  auto* ours = dynamic_cast<mlcp::bullet::ConstraintSolver*>(timed->inner());
  auto* stock = dynamic_cast<sc::StockMlcp*>(timed->inner());
  w.step(settle);  // untimed: the pyramid comes to rest under this solver
  const double seconds0 = timed->seconds, cpu0 = timed->cpuSeconds;
  const mlcp::bullet::StepStats totals0 = ours ? ours->totals() : mlcp::bullet::StepStats();
  const int stockFallbacks0 = stock ? stock->fallbacks() : 0;

  Row row;
  double measure = 0, worst = 0;
  int done = 0;
  for (; done < steps; ++done) {
    const double before = timed->seconds;
    w.step();
    double m = 0, r = NAN;
    if (ours) {
      m = ours->lastStep().measureSeconds;
      r = ours->lastStep().residual;
      row.rows = ours->lastStep().rows;
      row.iterations += ours->lastStep().iterations;
    } else if (stock) {
      m = stock->stepMeasureSeconds();
      r = stock->stepResidual();
    }
    measure += m;
    if (!(r <= worst)) worst = r;
    if (timed->seconds - before - m > 1.0) {
      ++done;
      row.note = "stopped: > 1 s/step";
      break;
    }
  }
  row.ms = (timed->seconds - seconds0 - measure) * 1e3 / done;
  row.cpuMs = (timed->cpuSeconds - cpu0 - measure) * 1e3 / done;
  row.residual = worst;
  row.iterations /= done;
  if (ours) {
    row.fallbacks = ours->totals().fallbacks - totals0.fallbacks;
    row.assembleMs = (ours->totals().assembleSeconds - totals0.assembleSeconds) * 1e3 / done;
    row.solveMs = (ours->totals().seconds - totals0.seconds) * 1e3 / done;
  }
  if (stock) row.fallbacks = stock->fallbacks() - stockFallbacks0;
  return row;
}

// Ours pgs against SI at the same sweep count (SI's m_numIterations = pgs sweeps; SI's early
// stop, m_leastSquaresResidualThreshold = 0, needs an exactly zero residual and does not happen
// here), on copies of the same pyramid stepped alternately so that machine noise hits both
// alike. Time is the CPU time of whole solveGroup calls (Bullet's row setup, the solve, the
// write-back; pgs includes its own residual check), median over the steps: on a shared machine
// wall time mostly measures the other processes. The stock SI solver is timed; SI's residual
// comes from a third copy running SI inside our drop-in ("si-stats"), untimed. Ours starts
// where SI starts (Settings::siStart: same sweeps, same start); a fourth copy, untimed, gives
// the residual of ours started from the cached impulses (the adapter's default).
struct Pair {
  // Residuals: worst over the steps, and the median of the steps' residuals.
  double siMs = NAN, pgsMs = NAN, siResidual = 0, pgsResidual = 0, cachedResidual = 0;
  double siMedian = NAN, pgsMedian = NAN, cachedMedian = NAN;
  // Medians of the solver stages alone (wall time): SI's iterations (in the "si-stats" copy) and
  // our stages 2-7 (islands, solve, check, store impulses); the rest of solveGroup is Bullet's
  // row setup and finish, the same code in both.
  double siIterMs = NAN, pgsStagesMs = NAN;
  int rows = 0;
  // Problems ours solved per step (islands and their split-impulse twins), mean over the steps.
  double problems = 0;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}

Pair pgsVersusSi(int boxes, int warmup, int steps, int sweeps) {
  sc::World si, siStats, ours, cached;
  for (sc::World* w : {&si, &siStats, &ours, &cached}) {
    w->info().m_globalCfm = 1e-5;
    w->info().m_numIterations = sweeps;
    sc::pyramid(*w, boxes);
    w->step(warmup);
  }
  mlcp::bullet::Settings s;
  s.cfm = mlcp::bullet::CfmModel::StockMlcp;
  s.engineIterations = true;
  s.acceptResidual = INFINITY;
  s.fallback = "";
  si.setSolver(std::make_unique<Timed>(sc::makeBulletSolver("si")));
  siStats.setSolver(sc::makeBulletSolver("si-stats", s));
  cached.setSolver(sc::makeBulletSolver("pgs", s));
  s.siStart = true;
  ours.setSolver(std::make_unique<Timed>(sc::makeBulletSolver("pgs", s)));
  auto* fromCached = static_cast<mlcp::bullet::ConstraintSolver*>(cached.solver());
  auto* stats = static_cast<mlcp::bullet::ConstraintSolver*>(siStats.solver());
  auto* timedSi = static_cast<Timed*>(si.solver());
  auto* timedPgs = static_cast<Timed*>(ours.solver());
  auto* pgs = static_cast<mlcp::bullet::ConstraintSolver*>(timedPgs->inner());
  Pair out;
  std::vector<double> tSi, tPgs, tSiIter, tStages, rSi, rPgs, rCached;
  for (int k = 0; k < steps; ++k) {
    double before = timedSi->cpuSeconds;
    si.step();
    tSi.push_back((timedSi->cpuSeconds - before) * 1e3);
    before = timedPgs->cpuSeconds;
    ours.step();
    tPgs.push_back((timedPgs->cpuSeconds - before) * 1e3);
    tStages.push_back(pgs->lastStep().seconds * 1e3);
    siStats.step();
    tSiIter.push_back(stats->lastStep().seconds * 1e3);
    rSi.push_back(stats->lastStep().residual);
    rPgs.push_back(pgs->lastStep().residual);
    out.siResidual = std::max(out.siResidual, rSi.back());
    out.pgsResidual = std::max(out.pgsResidual, rPgs.back());
    cached.step();
    rCached.push_back(fromCached->lastStep().residual);
    out.cachedResidual = std::max(out.cachedResidual, rCached.back());
    out.rows = pgs->lastStep().rows;
    out.problems += double(pgs->lastStep().islands) / steps;
  }
  out.siMs = median(tSi);
  out.pgsMs = median(tPgs);
  out.siIterMs = median(tSiIter);
  out.siMedian = median(rSi);
  out.pgsMedian = median(rPgs);
  out.cachedMedian = median(rCached);
  out.pgsStagesMs = median(tStages);
  return out;
}

std::vector<int> parseSizes(const std::string& s) {
  std::vector<int> out;
  std::size_t p = 0;
  while (p < s.size()) {
    std::size_t q = s.find(',', p);
    if (q == std::string::npos) q = s.size();
    out.push_back(std::stoi(s.substr(p, q - p)));
    p = q + 1;
  }
  return out;
}

// Whether `label` contains one of the comma-separated parts of `only` (all when it is empty).
bool selected(const std::string& label, const std::string& only) {
  if (only.empty()) return true;
  std::size_t p = 0;
  while (p <= only.size()) {
    std::size_t q = only.find(',', p);
    if (q == std::string::npos) q = only.size();
    if (q > p && label.find(only.substr(p, q - p)) != std::string::npos) return true;
    p = q + 1;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Per-step solver time and residual: our solvers vs Bullet's, on box pyramids."};
  int steps = 20, warmup = 30, settle = 0;
  std::string sizes = "15,55,210", csvPath, only;
  app.add_option("--steps", steps, "timed steps per configuration")->capture_default_str();
  app.add_option("--warmup", warmup, "SI steps before timing")->capture_default_str();
  app.add_option("--settle", settle, "untimed steps of each configuration's own solver")
      ->capture_default_str();
  app.add_option("--sizes", sizes, "pyramid sizes (triangular numbers)")->capture_default_str();
  app.add_option("--csv", csvPath, "also write the table as CSV");
  app.add_option("--only", only,
                 "run only configurations whose label contains one of these comma-separated "
                 "parts (e.g. \"ours dantzig,MLCP-Dantzig\")");
  bool pair = false;
  std::string sweeps = "10,50";
  app.add_flag("--pgs-vs-si", pair,
               "only the table of ours pgs against SI at equal sweeps, stepped alternately");
  app.add_option("--sweeps", sweeps, "sweep counts of --pgs-vs-si")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (pair) {
    // Which machine code RowPgs runs (MLCP_CPU_PATH=baseline forces the baseline).
    std::printf("RowPgs cpu path: %s\n", mlcp::toString(mlcp::cpuPath()));
    std::printf(
        "| boxes | rows | sweeps | SI ms/step | ours pgs ms/step | pgs / SI | SI residual "
        "worst (median) | pgs residual worst (median) | pgs from the cached impulses | "
        "SI iterations ms | ours stages ms | ours problems/step |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int boxes : parseSizes(sizes))
      for (int n : parseSizes(sweeps)) {
        const Pair p = pgsVersusSi(boxes, warmup, steps, n);
        std::printf(
            "| %d | %d | %d | %.3f | %.3f | %.2fx | %.2e (%.1e) | %.2e (%.1e) | %.2e (%.1e) | "
            "%.3f | %.3f | %.2f |\n",
            boxes, p.rows, n, p.siMs, p.pgsMs, p.pgsMs / p.siMs, p.siResidual, p.siMedian,
            p.pgsResidual, p.pgsMedian, p.cachedResidual, p.cachedMedian, p.siIterMs, p.pgsStagesMs,
            p.problems);
        std::fflush(stdout);
      }
    return 0;
  }

  const std::vector<Config> configs = {
      {"SI (stock)", "si-stats", false},       {"ours pgs", "pgs", false},
      {"MLCP-PGS (stock)", "mlcp-pgs", false}, {"ours dantzig", "dantzig", true},
      {"ours newton", "newton", false},        {"MLCP-Dantzig (stock)", "mlcp-dantzig", true},
      {"ours lemke", "lemke", true},           {"MLCP-Lemke (stock)", "mlcp-lemke", true},
  };
  std::ofstream csv;
  if (!csvPath.empty()) {
    csv.open(csvPath);
    csv << "boxes,rows,solver,ms_per_step,solve_ms,worst_residual,fallbacks,iterations,"
           "assemble_ms,note\n";
  }
  std::map<std::string, std::pair<int, double>> previous;  // label -> (rows, ms)
  for (int boxes : parseSizes(sizes)) {
    std::map<std::string, Row> rows;
    int n = 0;
    std::printf(
        "\npyramid of %d boxes (%d warm-up SI steps, %d untimed own steps, %d timed steps, "
        "dt 1/60, 10 iterations, globalCfm 1e-5)\n",
        boxes, warmup, settle, steps);
    std::printf("%-22s %10s %10s %12s %10s %10s %12s %10s  %s\n", "solver", "ms/step", "solve ms",
                "residual", "fallbacks", "iter/step", "assemble ms", "cpu ms", "note");
    for (const Config& c : configs) {
      if (!selected(c.label, only)) continue;
      Row r;
      auto prev = previous.find(c.label);
      const double predicted =
          (c.pivoting && prev != previous.end() && n > 0)
              ? prev->second.second * std::pow(double(n) / prev->second.first, 3) / 1e3
              : 0;
      if (prev != previous.end() && prev->second.second < 0) {
        r.note = "skipped: smaller size already > 1 s/step";
      } else if (predicted > 1.0) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "skipped: predicted %.0f s/step (> 1 s)", predicted);
        r.note = buf;
      } else {
        r = run(c, boxes, warmup, settle, steps);
      }
      if (r.rows > 0) n = r.rows;
      previous[c.label] = {std::max(n, 1),
                           r.note.rfind("skipped", 0) == 0 || r.ms > 1e3 ? -1.0 : r.ms};
      rows[c.label] = r;
      std::printf("%-22s %10.3f %10.3f %12.2e %10d %10d %12.3f %10.3f  %s\n", c.label.c_str(), r.ms,
                  r.solveMs, r.residual, r.fallbacks, r.iterations, r.assembleMs, r.cpuMs,
                  r.note.c_str());
      std::fflush(stdout);
      if (csv)
        csv << boxes << ',' << n << ',' << c.label << ',' << r.ms << ',' << r.solveMs << ','
            << r.residual << ',' << r.fallbacks << ',' << r.iterations << ',' << r.assembleMs
            << ",\"" << r.note << "\"\n";
    }
    std::printf("rows per step: %d\n", n);
    const Row& si = rows["SI (stock)"];
    const Row& pgs = rows["ours pgs"];
    const Row& dz = rows["ours dantzig"];
    const Row& nw = rows["ours newton"];
    const Row& sdz = rows["MLCP-Dantzig (stock)"];
    if (std::isfinite(pgs.ms) && std::isfinite(si.ms))
      std::printf("ratio ours pgs / SI time (same 10 sweeps): %.2fx\n", pgs.ms / si.ms);
    if (std::isfinite(sdz.ms) && std::isfinite(dz.ms))
      std::printf("speed-up ours dantzig vs stock MLCP-Dantzig: %.1fx\n", sdz.ms / dz.ms);
    if (std::isfinite(sdz.ms) && std::isfinite(nw.ms))
      std::printf("speed-up ours newton vs stock MLCP-Dantzig: %.1fx\n", sdz.ms / nw.ms);
    if (std::isfinite(sdz.cpuMs) && std::isfinite(dz.cpuMs))
      std::printf("same in CPU time (cpu ms): %.1fx\n", sdz.cpuMs / dz.cpuMs);
  }
  return 0;
}
