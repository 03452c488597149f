// Scene files in the engines (mlcp::bullet::loadWorld, mlcp::ode::loadWorld): every scene runs
// without NaN, a resting box stays put, the inclines stick and slide as promised, the hinge and
// slider motors drive into their limits with the scene's sign conventions, stock solver names, a
// pendulum's period, the pendulum chain's joints and energy, the sphere pit's spheres kept apart.
#include "mlcp/scene/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/scene_engines.hpp"
#include "mlcp/scene/scene.hpp"

namespace {

using mlcp::scene::BodyState;
using mlcp::scene::RunSettings;
using mlcp::scene::Scene;
using mlcp::scene::Vec3;
using mlcp::scene::World;

const std::string kScenes = std::string(MLCP_SOURCE_DIR) + "/scenes";

using Loader = mlcp::test::SceneLoader;

std::vector<std::pair<std::string, Loader>> engines() { return mlcp::test::sceneEngines(); }

Scene load(const std::string& name) { return mlcp::scene::loadScene(kScenes + "/" + name); }

int onlyDynamicBody(const Scene& s) {
  int found = -1;
  for (std::size_t i = 0; i < s.bodies.size(); ++i)
    if (!s.bodies[i].isStatic()) {
      EXPECT_EQ(found, -1) << s.name << " has more than one dynamic body";
      found = static_cast<int>(i);
    }
  return found;
}

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

// Few steps for the big scenes: the suite also runs under sanitizers.
int stepsFor(const Scene& s) {
  const int n = s.dynamicBodyCount();
  return n > 500 ? 1 : n > 150 ? 2 : n > 30 ? 10 : 60;
}

TEST(SceneWorlds, EverySceneFileIsRun) {
  EXPECT_GE(mlcp::scene::listSceneFiles(kScenes).size(), 24u);
  EXPECT_FALSE(engines().empty());
}

// One test per scene file (in parallel under ctest; the big ones take a step or two only).
class EveryScene : public testing::TestWithParam<std::string> {};

TEST_P(EveryScene, RunsInEveryEngineWithoutNaN) {
  const Scene s = mlcp::scene::loadScene(GetParam());
  for (const auto& [engine, loader] : engines()) {
    RunSettings run = RunSettings::fromScene(s);
    run.solver = "pgs";
    // No fallback: Bullet's would re-solve most pyramid steps with 1000 sweeps (slow under
    // sanitizers); this test is about loading and stepping, not accuracy.
    run.fallback = "";
    std::unique_ptr<World> world;
    try {
      world = loader(s, run);
    } catch (const mlcp::scene::Unsupported& e) {
      // six_dof_spring in ODE; content_test checks which scenes an engine refuses.
      EXPECT_EQ(std::string(e.what()).find("unsupported in "), 0u) << e.what();
      continue;
    }
    const int steps = stepsFor(s);
    for (int i = 0; i < steps; ++i) world->step();
    EXPECT_EQ(world->stepsTaken(), steps);
    const auto states = world->states();
    ASSERT_EQ(states.size(), s.bodies.size());
    for (std::size_t i = 0; i < states.size(); ++i)
      EXPECT_TRUE(mlcp::scene::isFinite(states[i])) << engine << " " << s.name << " body " << i;
    const auto& m = world->last();
    EXPECT_TRUE(std::isfinite(m.energy) && std::isfinite(m.momentum)) << engine << " " << s.name;
    EXPECT_TRUE(std::isfinite(m.residual)) << engine << " " << s.name;
    // Nothing in these scenes moves faster than free fall from a few metres.
    EXPECT_LT(m.maxSpeed, 20.0) << engine << " " << s.name;
    // A wrong shape, pose or plane shows as deep contacts. Not for the mass-ratio scenes: pgs
    // with 50 sweeps and no fallback lets their heavy tops sink (a solver limit, not a bug).
    // Nor hull_stack in ODE, whose convex-convex collider gives one point per resting face pair
    // (see content_test's HullStackStands).
    if (s.name != "mass_ratio_stack" && s.name != "heavy_on_small" &&
        !(s.name == "hull_stack" && engine == "ode")) {
      EXPECT_LT(m.maxPenetration, 0.05) << engine << " " << s.name;
    }
    EXPECT_STREQ(world->engine(), engine.c_str());
  }
}

INSTANTIATE_TEST_SUITE_P(SceneFiles, EveryScene,
                         testing::ValuesIn(mlcp::scene::listSceneFiles(kScenes)),
                         [](const testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param.substr(info.param.rfind('/') + 1);
                           name = name.substr(0, name.size() - 5);  // ".json"
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

TEST(SceneWorlds, RestingBoxStaysPut) {
  const Scene s = load("resting_box.json");
  const int box = onlyDynamicBody(s);
  for (const auto& [engine, loader] : engines()) {
    auto world = loader(s, RunSettings::fromScene(s));
    for (int i = 0; i < 60; ++i) world->step();
    const BodyState b = world->states()[box];
    EXPECT_LT(distance(b.position, s.bodies[box].position), 2e-3) << engine;
    EXPECT_LT(world->last().maxSpeed, 1e-2) << engine;
    EXPECT_GT(world->last().contacts, 0) << engine;
  }
}

TEST(SceneWorlds, InclineSticksAndSlides) {
  const Scene stick = load("incline_stick.json");
  const Scene slide = load("incline_slide.json");
  const double seconds = 60 * slide.settings.timeStep;
  const double promised = 0.5 * 3.217 * seconds * seconds;  // scenes/README.md
  for (const auto& [engine, loader] : engines()) {
    {
      const int box = onlyDynamicBody(stick);
      auto world = loader(stick, RunSettings::fromScene(stick));
      for (int i = 0; i < 60; ++i) world->step();
      EXPECT_LT(distance(world->states()[box].position, stick.bodies[box].position), 0.01)
          << engine;
    }
    {
      const int box = onlyDynamicBody(slide);
      auto world = loader(slide, RunSettings::fromScene(slide));
      for (int i = 0; i < 60; ++i) world->step();
      const double moved = distance(world->states()[box].position, slide.bodies[box].position);
      EXPECT_NEAR(moved, promised, 0.1 * promised) << engine;
    }
  }
}

// The scene's signs: a positive hinge angle / slider offset is A's rotation / displacement
// relative to B (here the world) about / along the axis; the motors drive into the upper limit.
TEST(SceneWorlds, MotorsDriveIntoTheirUpperLimitsWithTheSceneSigns) {
  const Scene hinge = load("hinge_motor_limits.json");
  const Scene slider = load("slider_motor_limits.json");
  for (const auto& [engine, loader] : engines()) {
    {
      const auto& j = hinge.joints.at(0);
      auto world = loader(hinge, RunSettings::fromScene(hinge));
      for (int i = 0; i < 90; ++i) world->step();
      const auto q = mlcp::scene::relative(world->states()[j.body0].orientation,
                                           hinge.bodies[j.body0].orientation);
      EXPECT_NEAR(mlcp::scene::twistAngle(q, j.axis), j.limits.upper, 0.05) << engine;
      EXPECT_LT(world->last().jointError, 0.01) << engine;
    }
    {
      const auto& j = slider.joints.at(0);
      auto world = loader(slider, RunSettings::fromScene(slider));
      for (int i = 0; i < 90; ++i) world->step();
      const Vec3 p = world->states()[j.body0].position, p0 = slider.bodies[j.body0].position;
      const double offset =
          (p[0] - p0[0]) * j.axis[0] + (p[1] - p0[1]) * j.axis[1] + (p[2] - p0[2]) * j.axis[2];
      EXPECT_NEAR(offset, j.limits.upper, 0.02) << engine;
      EXPECT_LT(world->last().jointError, 0.01) << engine;
    }
  }
}

TEST(SceneWorlds, StockSolversRunAndUnknownNamesAreRejected) {
  const Scene s = load("resting_box.json");
  std::vector<std::pair<std::string, std::string>> stock{{"bullet", "bullet-si"},
                                                         {"bullet", "bullet-nncg"},
                                                         {"bullet", "bullet-mlcp-pgs"},
                                                         {"bullet", "bullet-mlcp-dantzig"},
                                                         {"bullet", "bullet-mlcp-lemke"},
                                                         {"ode", "ode-world"},
                                                         {"ode", "ode-quick"},
                                                         {"bullet", "dantzig"},
                                                         {"ode", "dantzig"}};
  const int box = onlyDynamicBody(s);
  for (const auto& [engine, loader] : engines()) {
    for (const auto& [e, name] : stock) {
      if (e != engine) continue;
      RunSettings run = RunSettings::fromScene(s);
      run.solver = name;
      auto world = loader(s, run);
      for (int i = 0; i < 10; ++i) world->step();
      EXPECT_LT(distance(world->states()[box].position, s.bodies[box].position), 2e-3)
          << engine << " " << name;
      EXPECT_GT(world->last().stepMs, 0) << engine << " " << name;
    }
    RunSettings run;
    run.solver = "nosuch";
    EXPECT_THROW(loader(s, run), std::invalid_argument) << engine;
    run.solver = engine == "bullet" ? "ode-world" : "bullet-si";
    EXPECT_THROW(loader(s, run), std::invalid_argument) << engine;
  }
}

// A 1 m pendulum (a small ball on a ball joint) released horizontally: the loaders place the
// anchor where the scene says (the ball stays 1 m from it) and the swing has the closed-form
// period T = 4 sqrt(L/g) K(sin 45 deg) = 2.3687 s (L = 1.001 m with the ball's own inertia), so
// x first crosses 0 at T/4 = 0.5922 s.
TEST(SceneWorlds, PendulumKeepsItsAnchorAndSwingsWithTheClosedFormPeriod) {
  const Scene s = mlcp::scene::parseScene(R"({"format": "mlcp-scene/1",
      "settings": {"time_step": 0.002},
      "bodies": [{"name": "bob", "shape": {"type": "sphere", "radius": 0.05}, "mass": 1,
                  "position": [1, 0, 6]}],
      "joints": [{"type": "ball", "bodies": ["bob"], "anchor": [0, 0, 6]}]})");
  for (const auto& [engine, loader] : engines()) {
    RunSettings run = RunSettings::fromScene(s);
    run.solver = "dantzig";
    auto world = loader(s, run);
    double crossing = -1, x0 = 1;
    for (int i = 1; i <= 400 && crossing < 0; ++i) {
      world->step();
      const Vec3 p = world->states()[0].position;
      EXPECT_NEAR(distance(p, {0, 0, 6}), 1.0, 1e-3) << engine << " step " << i;
      if (p[0] <= 0) crossing = (i - 1 + x0 / (x0 - p[0])) * s.settings.timeStep;
      x0 = p[0];
    }
    EXPECT_NEAR(crossing, 0.5922, 0.005) << engine;
  }
}

// The pendulum chain (100:1 end mass) holds together in both engines with an exact solver: its
// time step is small enough for the stiff links (at 1/60 s the joints came meters apart with
// every solver and the energy grew fivefold). 300 steps take it through the fast part of its
// fall.
TEST(SceneWorlds, PendulumChainHoldsTogetherAndKeepsItsEnergy) {
  const Scene s = load("pendulum_chain.json");
  for (const auto& [engine, loader] : engines()) {
    RunSettings run = RunSettings::fromScene(s);
    run.solver = "dantzig";
    auto world = loader(s, run);
    world->step();
    const double e0 = world->last().energy;
    double worstJoint = 0, worstEnergy = 0;
    for (int i = 1; i < 300; ++i) {
      world->step();
      worstJoint = std::max(worstJoint, world->last().jointError);
      worstEnergy = std::max(worstEnergy, std::abs(world->last().energy - e0));
    }
    EXPECT_LT(worstJoint, 5e-3) << engine;
    EXPECT_LT(worstEnergy, 0.02 * std::abs(e0)) << engine;
  }
}

// The sphere pit's spheres stay apart: no sphere sinks into another or into a wall (ODE's hash
// space once missed some sphere pairs: a sphere fell through the one below it, 0.5 m deep).
// Checked from the body states, not only from the contacts the engine reports.
TEST(SceneWorlds, SpherePitSpheresStayApart) {
  const Scene s = load("sphere_pit.json");
  std::vector<int> balls;
  for (std::size_t i = 0; i < s.bodies.size(); ++i)
    if (!s.bodies[i].isStatic()) balls.push_back(static_cast<int>(i));
  ASSERT_EQ(balls.size(), 216u);
  const double r = s.bodies[balls[0]].shape.radius;
  const mlcp::scene::Body& wall = s.bodies[s.findBody("wall_px")];
  const double inside = wall.position[0] - 0.5 * wall.shape.size[0];  // the walls' inner faces
  for (const auto& [engine, loader] : engines()) {
    RunSettings run = RunSettings::fromScene(s);
    run.solver = "dantzig";
    auto world = loader(s, run);
    double deepest = 0;
    for (int i = 0; i < 50; ++i) {
      world->step();
      deepest = std::max(deepest, world->last().maxPenetration);
    }
    EXPECT_LT(deepest, 0.01) << engine;
    const auto states = world->states();
    double closest = 1e9;
    for (std::size_t a = 0; a < balls.size(); ++a)
      for (std::size_t b = a + 1; b < balls.size(); ++b)
        closest = std::min(closest, distance(states[balls[a]].position, states[balls[b]].position));
    EXPECT_GT(closest, 2 * r - 0.01) << engine;
    for (int i : balls) {
      const Vec3& p = states[i].position;
      EXPECT_GT(p[2], r - 0.01) << engine << " " << s.bodies[i].name;
      EXPECT_LT(std::max(std::abs(p[0]), std::abs(p[1])), inside - r + 0.01)
          << engine << " " << s.bodies[i].name;
    }
  }
}

TEST(SceneWorlds, MeasuresOfKnownStates) {
  Scene s = mlcp::scene::parseScene(R"({"format": "mlcp-scene/1", "bodies": [
      {"name": "a", "shape": {"type": "sphere", "radius": 0.5}, "mass": 2, "position": [0, 0, 1]},
      {"name": "b", "shape": {"type": "box", "size": [1, 1, 1]}, "mass": 1, "position": [2, 0, 1]}],
      "joints": [{"type": "ball", "bodies": ["a", "b"], "anchor": [1, 0, 1]},
                 {"type": "slider", "bodies": ["b"], "axis": [1, 0, 0]}]})");
  std::vector<BodyState> states(2);
  states[0].position = {0, 0, 1};
  states[0].velocity = {3, 0, 0};
  states[0].angularVelocity = {0, 0, 2};
  states[1].position = {2.5, 0.1, 1};  // slid 0.5 along the axis, 0.1 off it
  states[1].velocity = {-6, 0, 0};
  const std::vector<std::pair<Vec3, Vec3>> anchors{{{1, 0, 0}, {-1, 0, 0}}, {{0, 0, 0}, {2, 0, 1}}};
  mlcp::scene::StepMeasures m;
  mlcp::scene::measureStates(s, states, anchors, m);
  const double inertia = 0.4 * 2 * 0.25;
  EXPECT_NEAR(m.energy, 0.5 * 2 * 9 + 0.5 * inertia * 4 + 0.5 * 36 + 9.81 * (2 + 1), 1e-12);
  EXPECT_NEAR(m.momentum, 0, 1e-12);
  EXPECT_NEAR(m.maxSpeed, 6, 1e-12);
  // Ball: a's anchor (1, 0, 1) against b's (1.5, 0.1, 1): 0.51; slider: 0.1 off the axis.
  EXPECT_NEAR(m.jointError, std::sqrt(0.25 + 0.01), 1e-12);
}

}  // namespace
