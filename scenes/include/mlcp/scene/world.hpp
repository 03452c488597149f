// mlcp/scene/world.hpp: a scene loaded into an engine, behind one engine-free interface.
//
//     mlcp::scene::Scene scene = mlcp::scene::loadScene("scenes/stack_10.json");
//     auto world = mlcp::bullet::loadWorld(scene, RunSettings::fromScene(scene));  // or ode::
//     for (int i = 0; i < 100; ++i) {
//       world->step();
//       const StepMeasures& m = world->last();   // solver ms, residual, energy, ...
//     }
//
// The engine loaders (adapters/bullet, adapters/ode) subclass World; `mlcp run`, the scene
// tests and the sweeps see only this header. Measures that depend on the engine's solver
// (time, residual, iterations, status, fallbacks) and on its contacts (penetration) come from
// the engine; the others are computed here from the body states alone, so both engines are
// measured by the same code:
//   energy        sum over dynamic bodies of 1/2 m |v|^2 + 1/2 w^T R I R^T w - m g . p  (J)
//   momentum      |sum m v|  (kg m/s)
//   max_speed     max |v| over dynamic bodies  (m/s)
//   joint_error   max over joints of the drift of the joint's anchor: the anchor is fixed in
//                 each body's frame at creation; the error is the distance between its two
//                 world positions now (for a slider only the part perpendicular to the axis,
//                 which is free to slide); orientation drift is not measured; joints that
//                 let their anchors part (gears, hinge-2 suspensions, six_dof joints with a
//                 linear axis not locked) are left out  (m)
#pragma once

#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mlcp/island/row_solver.hpp"
#include "mlcp/scene/scene.hpp"

namespace mlcp::scene {

// What an engine loader throws for a scene feature that engine cannot express, with a message
// "unsupported in ENGINE: what": never a silent drop. An invalid_argument, as an unknown solver
// name is (the CLI exits 2 on both).
class Unsupported : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// What a run uses: the solver and its limits. fromScene() takes the scene's `solver` defaults.
struct RunSettings {
  // A core registry name (through our adapters; "auto" chooses per island) or an engine's
  // stock solver name ("bullet-si", "ode-world", ...; each loader lists its own). Default "auto".
  std::string solver = "auto";
  // Sweeps (iterative) or outer iterations (pivoting); stock iterative solvers' iteration count.
  // Default 50.
  int iterations = 50;
  // Options::tolerance, scaled natural-map residual. Default 1e-6.
  double tolerance = 1e-6;
  // Start each step from the last step's impulses. Default true.
  bool warmStart = true;
  // Core solver run when the primary's answer is rejected, "" for none (core solvers only).
  // Default "pgs" (the adapters' default, with the core's default options).
  std::string fallback = "pgs";
  // Largest accepted scaled residual, the same rule in both engines (mlcp::acceptable in
  // mlcp/island/row_solver.hpp: an answer that is not finite, is Failed, or whose recomputed
  // residual is above this goes to the fallback; the better answer is kept). Default 1e-3, the
  // adapters' mlcp::kDefaultAcceptResidual; +inf accepts any finite answer.
  double fallbackResidual = kDefaultAcceptResidual;
  // pgs/gs run exactly `iterations` sweeps, the residual checked once at the end, as the
  // engine's own solver runs its iteration count (RowSolverSettings::engineIterations, the
  // adapters' default for a drop-in; the loaders give the engine the same count). Default
  // false: a scene run sweeps toward `tolerance` within `iterations`.
  bool engineIterations = false;
  // Wall-clock budget of one step's solves in seconds, 0 for none (core solvers only;
  // RowSolverSettings::timeBudget). Default the adapters' kDefaultTimeBudget (0.05 s).
  double timeBudget = kDefaultTimeBudget;
  // Most block steps of newton's pivoting phase (RowSolverSettings::newton: pivotingSteps and
  // bodyPivotingSteps), 0 to turn it off; -1 for NewtonParams' defaults (40, 120 with the rows).
  int pivotingSteps = -1;
  // Friction model of contacts (mlcp/island/friction_model.hpp; core solvers only: a stock solver
  // with Cone is refused). Default Box.
  FrictionModel friction = FrictionModel::Box;
  // Friction directions per contact of the cone, in [3, 64]. Default kDefaultConeDirections (4).
  int frictionDirections = kDefaultConeDirections;

  static RunSettings fromScene(const Scene& scene);
};

struct BodyState {
  Vec3 position{0, 0, 0};         // centre of mass, world, m
  Quat orientation;               // body to world
  Vec3 velocity{0, 0, 0};         // m/s
  Vec3 angularVelocity{0, 0, 0};  // world, rad/s
};

inline constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();

// One step's measures (the columns of `mlcp run`'s CSV).
struct StepMeasures {
  double solverMs = 0;  // wall time of the constraint solve(s), ms
  double stepMs = 0;    // wall time of the whole step (collision, solve, integration), ms
  // Worst scaled natural-map residual of the step's problems; NaN when the solver's answer is
  // not measured (stock iterative solvers).
  double residual = kNotMeasured;
  int iterations = 0;  // summed over islands (stock iterative solvers: the fixed count)
  // Worst status over islands, mlcp::toString names ("converged", "max-iterations", ...).
  std::string status = "converged";
  int fallbacks = 0;
  // Islands whose applied answer still fails mlcp::acceptable after the fallback (Bullet's
  // StepStats::failures, ODE's IslandStats::accepted false); 0 for stock solvers, which do not
  // say.
  int unsolved = 0;
  // Which solver answered each island, counted: e.g. "dantzig:3 ldlt:1 none:2" (islands with
  // no rows are "none"); "" when the engine does not say (stock solvers).
  std::string choice;
  int contacts = 0;           // contact points this step
  double maxPenetration = 0;  // deepest contact of this step (before integration), m, >= 0
  double jointError = 0;      // m, see above
  double energy = 0;          // J
  double momentum = 0;        // kg m/s
  double maxSpeed = 0;        // m/s
};

class World {
 public:
  explicit World(const Scene& scene);
  virtual ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // One fixed step of scene().settings.timeStep; then last() holds its measures.
  void step();
  const StepMeasures& last() const { return last_; }
  int stepsTaken() const { return steps_; }
  const Scene& scene() const { return scene_; }

  // Every scene body (static ones included) in scene order.
  virtual std::vector<BodyState> states() const = 0;
  // "bullet" or "ode".
  virtual const char* engine() const = 0;

  // Asks the engine to write, during the next step(), each island's MLCP as an mlcp-problem/1
  // file in `folder` (named <scene>-<engine>-step<N>-island<K>.json, N = stepsTaken() before
  // that step, K counting the step's solves from 0). Returns false when this
  // engine/solver cannot (stock solvers): nothing is written then. The files written are
  // listed by capturedFiles() after that step.
  virtual bool captureNextStep(const std::string& folder) {
    (void)folder;
    return false;
  }
  virtual std::vector<std::string> capturedFiles() const { return {}; }

 protected:
  // Advances the engine by one step and fills the engine's measures (solver time, residual,
  // iterations, status, fallbacks, contacts, maxPenetration); the rest is filled by step().
  virtual void stepEngine(StepMeasures& m) = 0;

 private:
  Scene scene_;
  StepMeasures last_;
  int steps_ = 0;
  // Per joint: the anchor in body0's frame and in body1's frame (or the world).
  std::vector<std::pair<Vec3, Vec3>> anchors_;
};

// The body-state measures of a World (energy, momentum, max speed, joint error), exposed for
// tests. `anchors` as kept by World.
void measureStates(const Scene& scene, const std::vector<BodyState>& states,
                   const std::vector<std::pair<Vec3, Vec3>>& anchors, StepMeasures& m);

// What captureNextStep's files start with: folder/<scene>-<engine>-step<N>- (the engines' row
// solvers append island<K>.json).
std::string capturePrefix(const std::string& folder, const std::string& scene, const char* engine,
                          int step);

// Whether every number of the state is finite (a blown-up simulation is not).
bool isFinite(const BodyState& b);
bool isFinite(const std::vector<BodyState>& states);

// The rotation angle (rad) of q about the unit axis: 2 atan2(v . axis, w) of q = (w, v), in
// (-pi, pi]. For a body turning about one axis, the angle it has turned.
double twistAngle(const Quat& q, const Vec3& axis);
// q a^-1: the rotation taking orientation a to orientation q.
Quat relative(const Quat& q, const Quat& a);

}  // namespace mlcp::scene
