// Stability cells of `mlcp stability`: the stack scenes it builds, what it measures while a
// cell runs, and how a cell is classified. Kept apart from the command so that the
// classification is unit-tested (tests/run/stability_test.cpp).
//
// A cell is one run of a stack of 1 m cubes on the ground, at rest at the start, for a fixed
// simulated time. While it runs, every step records the largest speed, each box's distance
// from where it started (centre of mass, m), the deepest contact, and whether the step's
// solver failed (status failed / numerical-issue / unsupported) or took a fallback. The
// outcome is the first of these that holds:
//
//   exploded        a body state became non-finite, or some body moved faster than
//                   max_speed (default 25 m/s: free fall from the top of a 16-box stack reaches
//                   17.7 m/s, so only energy the solver made up gets there)
//   solver-failure  more than failure_share (default 10 %) of the steps had a failed status or
//                   a fallback to the secondary solver (stock Bullet MLCP: to SI)
//   collapsed       some box moved more than collapse_fraction (default 0.5) of its edge from
//                   its start, or a contact penetrated deeper than collapse_penetration
//                   (default 0.1 m, a tenth of the edge: the stack is being crushed)
//   drifting        the top box moved more than drift (default 0.02 m) but nothing collapsed:
//                   the stack stands, but wanders, sinks or leans
//   stable          none of the above
//
// The defaults were set against real runs (README, "Stability map"): a resting stack settles
// into its contacts by a few millimetres at most in both engines with a converged solver,
// which stays below the drift distance.
#pragma once

#include <string>
#include <vector>

#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"

namespace mlcp::cli {

enum class Outcome { Stable, Drifting, Collapsed, Exploded, SolverFailure };
// "stable", "drifting", "collapsed", "exploded", "solver-failure" (tools/chart.py's names).
const char* toString(Outcome outcome);

struct StabilityThresholds {
  // m/s; a body faster than this (or a non-finite state) makes the cell exploded. Default 25.
  double maxSpeed = 25;
  // Share of steps, in [0, 1], with a failed status or a fallback above which the cell is a
  // solver failure. Default 0.1.
  double failureShare = 0.1;
  // Fraction of a box's edge it may move from its start before the cell is collapsed.
  // Default 0.5.
  double collapseFraction = 0.5;
  // m; a deeper contact makes the cell collapsed. Default 0.1.
  double collapsePenetration = 0.1;
  // m; the top box moving farther than this (and nothing collapsing) makes the cell drifting.
  // Default 0.02.
  double drift = 0.02;
};

// What a cell measured over its run.
struct CellMeasures {
  int steps = 0;                    // steps taken
  bool finite = true;               // every body state stayed finite
  double maxSpeed = 0;              // m/s, largest over bodies and steps
  int failedSteps = 0;              // steps with a failed / numerical-issue / unsupported status
  int fallbackSteps = 0;            // steps with at least one fallback
  double maxDisplacementRatio = 0;  // largest over boxes and steps of distance moved / edge
  double topDisplacement = 0;       // m, the top box's largest distance from its start
  double maxPenetration = 0;        // m, deepest contact over the run
};

struct Classification {
  Outcome outcome = Outcome::Stable;
  // Why, in a few words without commas (a CSV field): "top box moved 0.034 m > 0.01 m".
  std::string reason;
};

Classification classify(const CellMeasures& m, const StabilityThresholds& t);

// A stack of `height` 1 m cubes resting on a ground plane, bottom box 1 kg, top box
// `massRatio` kg, masses growing geometrically in between (each box ratio^(1/(height-1)) times
// the one below). Default settings (erp 0.2) except the time step and the world cfm; the solver
// defaults are left to the caller's RunSettings. Throws std::invalid_argument for height < 1,
// massRatio <= 0 or a negative cfm.
//
// Why a small cfm (kStackCfm): the scenes' default 1e-5 is a contact spring of stiffness
// erp / (h cfm) = 1.2e6 N/m per row at 60 Hz, whatever the load, and a 16-box stack of 1 to
// 1000 kg (2.7 t) rests on it 10 cm lower than it was built: the exact solvers' answers (3e-13)
// "drifted" by that deflection, which measures the model, not the method. At 1e-9 the spring
// deflects 0.2 mm there, and what breaks is the methods.
inline constexpr double kStackCfm = 1e-9;
scene::Scene stackScene(const std::string& name, int height, double massRatio, double timeStep,
                        double cfm = kStackCfm);

// Follows a run of a scene step by step and fills CellMeasures (call observe() after every
// step with the world's states and measures).
class CellTracker {
 public:
  explicit CellTracker(const scene::Scene& s);
  void observe(const std::vector<scene::BodyState>& states, const scene::StepMeasures& m);
  const CellMeasures& measures() const { return m_; }

 private:
  const scene::Scene& scene_;
  std::vector<int> boxes_;  // dynamic bodies, bottom to top (scene order)
  std::vector<scene::Vec3> start_;
  CellMeasures m_;
};

}  // namespace mlcp::cli
