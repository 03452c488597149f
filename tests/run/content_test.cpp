// The scenes of the kinds of content real Bullet and ODE programs have (ragdoll piles, a plank
// bridge, a vehicle, 6-dof springs, gears, large stacks, convex hulls) in both engines with
// every core solver that applies: no exception, no NaN, no island left unsolved (the adapters'
// StepMeasures::unsolved: an answer still rejected after the fallback), nothing flying off.
// Then what each scene's new joint or shape must do: the gear turns the second disc at the
// ratio, the car rolls on its wheels, the hulls stand, the 6-dof springs hold their boxes, and
// what an engine cannot express is refused with "unsupported in ENGINE: ...".
//
// Combinations that fail today because of a known solver bug are skipped with the bug's name
// (kKnownFailures below); MLCP_RUN_KNOWN_FAILURES=1 in the environment runs them anyway.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "common/scene_engines.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"

namespace {

using mlcp::scene::BodyState;
using mlcp::scene::RunSettings;
using mlcp::scene::Scene;
using mlcp::scene::World;

const std::string kScenes = std::string(MLCP_SOURCE_DIR) + "/scenes";

// The scene's run settings without a time budget: these tests check what the solvers answer,
// which a budget would make depend on the machine's speed (sanitizer builds run 3-5x slower).
RunSettings unbudgeted(const Scene& s) {
  RunSettings run = RunSettings::fromScene(s);
  run.timeBudget = 0;
  return run;
}

Scene load(const std::string& name) {
  return mlcp::scene::loadScene(kScenes + "/" + name + ".json");
}

mlcp::test::SceneLoader loaderOf(const std::string& engine) {
  return mlcp::test::sceneLoader(engine);
}

struct Case {
  const char* scene;
  const char* engine;
  const char* solver;
  int steps;
};

// How gtest and ctest name a case: "ragdoll_pile in ode with dantzig, 60 steps".
void PrintTo(const Case& c, std::ostream* os) {
  *os << c.scene << " in " << c.engine << " with " << c.solver << ", " << c.steps << " steps";
}

// Small scenes take a second of simulated time (60 steps of 1/60 s: the ragdolls and crates
// land, the car rolls a wheel turn); the 1000- and 3000-box scenes a step or two with the cheap
// solvers only (`mlcp run` and tests/bench take them further, see docs/benchmarks.md).
std::vector<Case> cases() {
  std::vector<Case> out;
  auto add = [&](const char* scene, std::vector<const char*> engines,
                 std::vector<const char*> solvers, int steps) {
    for (const char* e : engines)
      if (loaderOf(e))
        for (const char* s : solvers) out.push_back({scene, e, s, steps});
  };
  const std::vector<const char*> both{"bullet", "ode"};
  add("ragdoll_pile", both, {"pgs", "dantzig", "auto"}, 60);
  add("plank_bridge", both, {"pgs", "dantzig", "lemke", "ldlt", "auto"}, 60);
  add("vehicle", both, {"pgs", "dantzig", "lemke", "ldlt", "auto"}, 60);
  // ODE has no 6-dof joint with springs: the loader refuses it (SixDofSpringIsUnsupportedInOde).
  add("six_dof_spring", {"bullet"}, {"pgs", "dantzig", "lemke", "ldlt", "auto"}, 60);
  add("gear_pair", both, {"pgs", "dantzig", "lemke", "ldlt", "auto"}, 60);
  add("hull_stack", both, {"pgs", "dantzig", "lemke", "auto"}, 60);
  add("stack_1000", both, {"pgs", "auto"}, 2);
  add("boxes_3000", both, {"pgs", "auto"}, 3);
  // Articulated bodies as jointed rigid bodies (bullet, ode) and as btMultiBodies
  // (bullet-multibody, through the multibody drop-in).
  for (const char* scene : {"arm_push", "legged_base", "spherical_chain", "limit_chain"})
    add(scene, {"bullet", "bullet-multibody", "ode"}, {"pgs", "dantzig", "lemke", "ldlt", "auto"},
        60);
  return out;
}

// Combinations that fail today, each with the known bug or limit it waits for. A case that
// crashes is not run; the others run in full (no NaN is still asserted) and skip at the end
// with their count of unsolved steps, or say that they now pass.
struct KnownFailure {
  const char* scene;
  const char* engine;
  const char* solver;
  const char* bug;
  bool crashes;
};
// The bridge's A is singular (pairs of ball joints on one axis, cfm 0 in Bullet); dantzig and
// lemke solve it through their regularised retries, these stay.
constexpr const char* kBridgePgs =
    "pgs convergence on the singular bridge: the 12-plank chain under two 10 kg crates needs ~1000 "
    "sweeps from zero to reach the 1e-3 acceptance (a captured Bullet step: 0.11 after 50 sweeps, "
    "0.044 after 100, 4.5e-4 after 1000), beyond 50 sweeps and the 100-sweep fallback (a method "
    "limit)";
constexpr const char* kBridgeLdlt =
    "ldlt refuses bounded rows: once the crates land (step 16) the islands have contacts, and the "
    "100-sweep pgs fallback misses the 1e-3 acceptance on the singular bridge (see kBridgePgs)";
constexpr const char* kPgsLimit =
    "pgs convergence: at the engine's count (the scene's 50 sweeps; no fallback, the same sweeps "
    "would repeat) pgs does not reach the 1e-3 acceptance on these large contact islands (a "
    "method limit; the slow-exact-solvers-on-large-islands work replaces pgs here)";
constexpr const char* kVehiclePgs =
    "pgs at QuickStep's count (the scene's 50 sweeps, w 1.3; no fallback: the same sweeps would "
    "repeat): the 200 kg chassis on 10 kg wheels gives A a condition number of 2.8e3 after "
    "diagonal scaling, and pgs needs ~1000 sweeps to reach the 1e-3 acceptance (a captured "
    "step: 0.02 after 50, 2.9e-4 after 1000; a method limit)";
constexpr const char* kVehicleLdlt =
    "ldlt refuses bounded rows (the wheels' contacts) and its pgs fallback, at QuickStep's 50 "
    "sweeps, misses the 1e-3 acceptance as pgs does (see kVehiclePgs)";
constexpr const char* kHullsPgs =
    "pgs at QuickStep's count (the scene's 50 sweeps, w 1.3; no fallback): ODE's one contact "
    "point per hull face pair tilts the stack, whose islands reach a condition number of 1.7e4 "
    "after diagonal scaling; two steps end at 1.1e-3, just above the 1e-3 acceptance (a method "
    "limit at the engine's count)";
constexpr const char* kChainPgs =
    "pgs convergence on jointed chains (the articulated scenes in maximal coordinates: 4 to 6 "
    "links, motors at their force bounds, limits, ground contacts): the worst step of 60 in "
    "Bullet ends at 0.65 (arm_push), 0.34 (limit_chain), 0.098 (legged_base) and 0.0076 "
    "(spherical_chain) after 50 sweeps and still at 0.016, 0.014, 0.0053 and 3.9e-5 after 1000, "
    "against the 1e-3 acceptance (a method limit: the exact solvers and auto hold every step)";
constexpr const char* kChainLdlt =
    "ldlt refuses bounded rows (limits, motors, contacts) and its pgs fallback misses the 1e-3 "
    "acceptance on the jointed chains (see kChainPgs)";
constexpr const char* kMultiBodyPgs =
    "pgs convergence in reduced coordinates (bullet-multibody: no joint rows, the limits, motors "
    "and contacts on the btMultiBody): at the scene's 50 sweeps 1 (arm_push), 12 (legged_base) "
    "and 31 (limit_chain) of 60 steps end above the 1e-3 acceptance (60 of 60 in maximal "
    "coordinates, kChainPgs; a method limit)";
constexpr const char* kMultiBodyLdlt =
    "ldlt refuses bounded rows and its pgs fallback misses the 1e-3 acceptance as pgs does (see "
    "kMultiBodyPgs)";
const KnownFailure kKnownFailures[] = {
    {"arm_push", "bullet-multibody", "pgs", kMultiBodyPgs, false},
    {"arm_push", "bullet-multibody", "ldlt", kMultiBodyLdlt, false},
    {"legged_base", "bullet-multibody", "pgs", kMultiBodyPgs, false},
    {"legged_base", "bullet-multibody", "ldlt", kMultiBodyLdlt, false},
    {"limit_chain", "bullet-multibody", "pgs", kMultiBodyPgs, false},
    {"limit_chain", "bullet-multibody", "ldlt", kMultiBodyLdlt, false},
    {"arm_push", "bullet", "pgs", kChainPgs, false},
    {"arm_push", "ode", "pgs", kChainPgs, false},
    {"arm_push", "bullet", "ldlt", kChainLdlt, false},
    {"arm_push", "ode", "ldlt", kChainLdlt, false},
    {"legged_base", "bullet", "pgs", kChainPgs, false},
    {"legged_base", "ode", "pgs", kChainPgs, false},
    {"legged_base", "bullet", "ldlt", kChainLdlt, false},
    {"legged_base", "ode", "ldlt", kChainLdlt, false},
    {"limit_chain", "bullet", "pgs", kChainPgs, false},
    {"limit_chain", "ode", "pgs", kChainPgs, false},
    {"limit_chain", "bullet", "ldlt", kChainLdlt, false},
    {"limit_chain", "ode", "ldlt", kChainLdlt, false},
    {"spherical_chain", "bullet", "pgs", kChainPgs, false},
    {"spherical_chain", "ode", "pgs", kChainPgs, false},
    {"vehicle", "ode", "pgs", kVehiclePgs, false},
    {"vehicle", "ode", "ldlt", kVehicleLdlt, false},
    {"hull_stack", "ode", "pgs", kHullsPgs, false},
    {"ragdoll_pile", "bullet", "pgs", kPgsLimit, false},
    {"ragdoll_pile", "ode", "pgs", kPgsLimit, false},
    {"plank_bridge", "bullet", "pgs", kBridgePgs, false},
    {"plank_bridge", "bullet", "ldlt", kBridgeLdlt, false},
    {"plank_bridge", "ode", "pgs", kBridgePgs, false},
    {"plank_bridge", "ode", "ldlt", kBridgeLdlt, false},
    {"hull_stack", "bullet", "pgs", kPgsLimit, false},
    {"stack_1000", "bullet", "pgs", kPgsLimit, false},
    {"stack_1000", "ode", "pgs", kPgsLimit, false},
};

const KnownFailure* knownFailure(const std::string& scene, const std::string& engine,
                                 const std::string& solver) {
  for (const KnownFailure& k : kKnownFailures)
    if (k.scene == scene && k.engine == engine && k.solver == solver) return &k;
  return nullptr;
}

bool runKnownFailures() { return std::getenv("MLCP_RUN_KNOWN_FAILURES") != nullptr; }

class SceneContent : public testing::TestWithParam<Case> {};

TEST_P(SceneContent, RunsWithoutNaNAndLeavesNoIslandUnsolved) {
  const Case& c = GetParam();
  const KnownFailure* known =
      runKnownFailures() ? nullptr : knownFailure(c.scene, c.engine, c.solver);
  if (known && known->crashes) GTEST_SKIP() << "known crash, waits for: " << known->bug;
  const Scene s = load(c.scene);
  RunSettings run = unbudgeted(s);
  run.solver = c.solver;
  auto world = loaderOf(c.engine)(s, run);
  // MLCP_CONTENT_STEPS=N runs N steps instead (the longer runs of docs/benchmarks.md).
  const char* stepsOverride = std::getenv("MLCP_CONTENT_STEPS");
  const int steps = stepsOverride ? std::atoi(stepsOverride) : c.steps;
  int unsolvedSteps = 0, firstUnsolved = -1, fallbacks = 0;
  double fastest = 0, solverMs = 0;
  for (int i = 0; i < steps; ++i) {
    world->step();
    const auto& m = world->last();
    if (m.unsolved > 0 && unsolvedSteps++ == 0) firstUnsolved = i;
    fallbacks += m.fallbacks;
    solverMs += m.solverMs;
    fastest = std::max(fastest, m.maxSpeed);
    ASSERT_TRUE(mlcp::scene::isFinite(world->states())) << "non-finite state at step " << i;
  }
  std::printf(
      "content %s %s %s: %d steps, %d with an island unsolved, %d fallbacks, solver %.3g ms/step, "
      "max speed %.3g m/s\n",
      c.scene, c.engine, c.solver, steps, unsolvedSteps, fallbacks,
      steps > 0 ? solverMs / steps : 0.0, fastest);
  // Nothing in these scenes moves faster than free fall from a few metres or the car's 2 m/s.
  EXPECT_LT(fastest, 15.0);
  if (known) {
    if (unsolvedSteps == 0)
      GTEST_SKIP() << "listed as a known failure but passes now: take it off kKnownFailures ("
                   << known->bug << ")";
    GTEST_SKIP() << "known failure (" << unsolvedSteps << " of " << steps
                 << " steps left an island unsolved), waits for: " << known->bug;
  }
  EXPECT_EQ(unsolvedSteps, 0) << "steps with an island left unsolved (first: step " << firstUnsolved
                              << ")";
}

INSTANTIATE_TEST_SUITE_P(Scenes, SceneContent, testing::ValuesIn(cases()),
                         [](const testing::TestParamInfo<Case>& info) {
                           std::string name = std::string(info.param.scene) + "_" +
                                              info.param.engine + "_" + info.param.solver;
                           std::replace(name.begin(), name.end(), '-', '_');  // bullet-multibody
                           return name;
                         });

std::vector<std::string> engines() {
  std::vector<std::string> e;
  for (const auto& [name, loader] : mlcp::test::sceneEngines()) e.push_back(name);
  return e;
}

double angularZ(const BodyState& b) { return b.angularVelocity[2]; }

// The motor drives the small disc at 2 rad/s; the gear of ratio 2 turns the big one at -1 rad/s
// (w_small . z = -2 w_big . z) in both engines.
TEST(SceneContentPhysics, GearTurnsTheSecondDiscAtTheRatio) {
  const Scene s = load("gear_pair");
  const int small = s.findBody("small"), big = s.findBody("big");
  for (const std::string& engine : engines()) {
    auto world = loaderOf(engine)(s, unbudgeted(s));
    for (int i = 0; i < 60; ++i) world->step();
    const auto st = world->states();
    EXPECT_NEAR(angularZ(st[small]), 2.0, 0.05) << engine;
    EXPECT_NEAR(angularZ(st[small]) / angularZ(st[big]), -2.0, 0.02) << engine;
  }
}

// The car keeps rolling on its four wheels: the chassis stays at its ride height, moves on at
// about 2 m/s and the wheels turn at v / r.
TEST(SceneContentPhysics, VehicleRollsOnItsWheels) {
  const Scene s = load("vehicle");
  const int chassis = s.findBody("chassis");
  for (const std::string& engine : engines()) {
    auto world = loaderOf(engine)(s, unbudgeted(s));
    for (int i = 0; i < 60; ++i) world->step();
    const auto st = world->states();
    const BodyState& c = st[chassis];
    EXPECT_NEAR(c.position[2], 0.6, 0.06) << engine << ": chassis height";
    EXPECT_GT(c.position[0], 1.5) << engine << ": distance rolled in 1 s";
    EXPECT_NEAR(c.velocity[0], 2.0, 0.3) << engine;
    for (const char* w : {"wheel_fl", "wheel_fr", "wheel_rl", "wheel_rr"}) {
      const BodyState& b = st[s.findBody(w)];
      EXPECT_NEAR(b.angularVelocity[1], b.velocity[0] / 0.3, 1.0) << engine << " " << w;
      EXPECT_NEAR(b.position[2], 0.3, 0.02) << engine << " " << w;
    }
  }
}

// The 6-dof springs hold both boxes near their rest poses, with every solver as with Bullet's
// own SI: the static sags are m g / k = 0.1 m (upper) and 0.2 m (lower, both springs), and the
// lightly damped springs swing to at most twice that (0.4 m); a box that falls goes 2.8 m.
class SixDofSprings : public testing::TestWithParam<const char*> {};

TEST_P(SixDofSprings, HoldTheBoxes) {
#ifdef MLCP_HAVE_BULLET
  const char* solver = GetParam();
  const KnownFailure* known =
      runKnownFailures() ? nullptr : knownFailure("six_dof_spring.hold", "bullet", solver);
  const Scene s = load("six_dof_spring");
  RunSettings run = unbudgeted(s);
  run.solver = solver;
  auto world = loaderOf("bullet")(s, run);
  for (int i = 0; i < 120; ++i) world->step();
  const auto st = world->states();
  double worst = 0;
  for (const char* name : {"upper", "lower"}) {
    const int b = s.findBody(name);
    worst = std::max(worst, std::abs(st[b].position[2] - s.bodies[b].position[2]));
  }
  if (known) GTEST_SKIP() << "known failure (dropped " << worst << " m), waits for: " << known->bug;
  EXPECT_LT(worst, 0.5);
#else
  GTEST_SKIP() << "needs Bullet";
#endif
}

INSTANTIATE_TEST_SUITE_P(Solvers, SixDofSprings,
                         testing::Values("bullet-si", "pgs", "dantzig", "lemke", "auto"),
                         [](const testing::TestParamInfo<const char*>& info) {
                           return std::string(info.param) == "bullet-si" ? std::string("bullet_si")
                                                                         : info.param;
                         });

// The top of the 8 hulls stays where it is. Not in ODE: its dCollideConvexConvex gives one
// contact point per resting face pair (cube hulls too), so its stacks tilt and sink 3 cm per
// pair whatever the solver; an engine limit, reported rather than asserted.
TEST(SceneContentPhysics, HullStackStands) {
  const Scene s = load("hull_stack");
  const int top = s.findBody("prism.7");
  for (const std::string& engine : engines()) {
    if (engine == "ode") continue;
    auto world = loaderOf(engine)(s, unbudgeted(s));
    for (int i = 0; i < 60; ++i) world->step();
    EXPECT_NEAR(world->states()[top].position[2], s.bodies[top].position[2], 0.01) << engine;
  }
}

// A capsule hanging from a cone-twist joint (swing 0.5 rad, twist 0.3 rad), swung about x
// and spun about its bone: a free ball joint would let it swing to ~1.4 rad and twist without
// end; the cone keeps both near their limits (Bullet's soft limits and ODE's stops overshoot a
// little) in both engines, so ODE's ball + Euler angular motor maps the same axes.
TEST(SceneContentPhysics, ConeTwistKeepsSwingAndTwistInItsCone) {
  const Scene s = mlcp::scene::parseScene(R"({"format": "mlcp-scene/1",
      "bodies": [{"name": "bone", "shape": {"type": "capsule", "radius": 0.05, "length": 0.4},
                  "mass": 1, "position": [0, 0, 1.75], "velocity": [0, 1.25, 0],
                  "angular_velocity": [5, 0, 5]}],
      "joints": [{"type": "cone_twist", "bodies": ["bone"], "anchor": [0, 0, 2],
                  "axis": [0, 0, -1], "cone": {"swing1": 0.5, "swing2": 0.5, "twist": 0.3}}]})");
  for (const std::string& engine : engines()) {
    auto world = loaderOf(engine)(s, unbudgeted(s));
    double swing = 0, twist = 0;
    for (int i = 0; i < 120; ++i) {
      world->step();
      const mlcp::scene::Quat q = world->states()[0].orientation;
      const mlcp::scene::Vec3 bone = mlcp::scene::rotate(q, {0, 0, -1});
      swing = std::max(swing, std::acos(std::clamp(-bone[2], -1.0, 1.0)));
      twist = std::max(twist, std::abs(mlcp::scene::twistAngle(q, {0, 0, -1})));
    }
    EXPECT_GT(swing, 0.4) << engine << ": it swings to its limit";
    EXPECT_LT(swing, 0.65) << engine;
    EXPECT_GT(twist, 0.2) << engine << ": it twists to its limit";
    EXPECT_LT(twist, 0.45) << engine;
  }
}

// A box hanging from a universal joint (axis x fixed in the box, axis2 y fixed in the world)
// spun about z and swung about x: the joint lets it swing but keeps the box's x axis
// perpendicular to the world's y (no turn about the third axis), and keeps its anchor. A free
// ball joint would turn 5 rad in the second; Bullet's universal (a btGeneric6DofConstraint,
// locked axis softness 0.5) lets the first step's spin through, 5 rad/s x 1/60 s = 0.083 rad.
TEST(SceneContentPhysics, UniversalJointSwingsButDoesNotTwist) {
  const Scene s = mlcp::scene::parseScene(R"({"format": "mlcp-scene/1",
      "bodies": [{"name": "box", "shape": {"type": "box", "size": [0.2, 0.2, 0.2]}, "mass": 1,
                  "position": [0, 0, 1.5], "velocity": [0, 1.5, 0], "angular_velocity": [3, 0, 5]}],
      "joints": [{"type": "universal", "bodies": ["box"], "anchor": [0, 0, 2], "axis": [1, 0, 0],
                  "axis2": [0, 1, 0]}]})");
  for (const std::string& engine : engines()) {
    auto world = loaderOf(engine)(s, unbudgeted(s));
    double swing = 0, twist = 0, drift = 0;  // twist: |y . (box's x axis)|
    for (int i = 0; i < 60; ++i) {
      world->step();
      const mlcp::scene::Quat q = world->states()[0].orientation;
      const mlcp::scene::Vec3 down = mlcp::scene::rotate(q, {0, 0, -1});
      swing = std::max(swing, std::acos(std::clamp(-down[2], -1.0, 1.0)));
      twist = std::max(twist, std::abs(mlcp::scene::rotate(q, {1, 0, 0})[1]));
      drift = std::max(drift, world->last().jointError);
    }
    EXPECT_GT(swing, 0.2) << engine;
    EXPECT_LT(twist, 0.1) << engine;
    EXPECT_LT(drift, 0.01) << engine;
  }
}

TEST(SceneContentPhysics, SixDofSpringIsUnsupportedInOde) {
#ifdef MLCP_HAVE_ODE
  const Scene s = load("six_dof_spring");
  try {
    loaderOf("ode")(s, unbudgeted(s));
    ADD_FAILURE() << "no error";
  } catch (const mlcp::scene::Unsupported& e) {
    EXPECT_NE(std::string(e.what()).find("unsupported in ODE: six_dof joint hanger"),
              std::string::npos)
        << e.what();
  }
#else
  GTEST_SKIP() << "needs ODE";
#endif
}

}  // namespace

namespace {

// Bullet's default cfm 0 on a 10-box stack: A is singular once the boxes rest (four coplanar
// contacts a face), as on Bullet's BasicDemo pile. With proximal named and no budget, every island
// of every step converges to the island tolerance (1e-6).
TEST(SceneContentPhysics, RestingStackWithoutCfmIsExactWithProximal) {
  const mlcp::test::SceneLoader bullet = loaderOf("bullet");
  if (!bullet) GTEST_SKIP() << "needs Bullet";
  Scene s = load("stack_10");
  s.settings.cfm = 0;
  RunSettings run = unbudgeted(s);
  run.solver = "proximal";
  auto world = bullet(s, run);
  for (int i = 0; i < 120; ++i) {
    world->step();
    const auto& m = world->last();
    ASSERT_TRUE(mlcp::scene::isFinite(world->states())) << "non-finite state at step " << i;
    EXPECT_EQ(m.status, "converged") << "step " << i << ": residual " << m.residual;
  }
}

}  // namespace
