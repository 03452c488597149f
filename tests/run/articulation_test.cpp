// Articulated scenes (mlcp/scene/articulation.hpp) in reduced coordinates (bullet-multibody) and
// maximal ones (bullet, ode): the same masses, links, joints and start poses in all three; bad
// articulations refused in one line; every articulated scene runs in every engine with the stock
// solver and auto; motors and limits with the same signs; and the joint-limit violation of
// limit_chain after settling, per engine, solver and Bullet's split impulse.
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "mlcp/bullet/scene_loader.hpp"
#include "mlcp/ode/scene_loader.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"

namespace {

using mlcp::bullet::Coordinates;
using mlcp::scene::BodyState;
using mlcp::scene::Quat;
using mlcp::scene::RunSettings;
using mlcp::scene::Scene;

const std::string kScenes = std::string(MLCP_SOURCE_DIR) + "/scenes";
const char* const kArticulated[] = {"arm_push", "legged_base", "spherical_chain", "limit_chain"};

Scene load(const std::string& name) {
  return mlcp::scene::loadScene(kScenes + "/" + name + ".json");
}

// The engines by name with a solver: Bullet's SI in both Bullet worlds, dWorldStep's in ODE.
std::unique_ptr<mlcp::scene::World> makeWorld(const std::string& engine, const Scene& s,
                                              const std::string& solver) {
  RunSettings run = RunSettings::fromScene(s);
  run.solver = solver;
  if (engine == "ode") return mlcp::ode::loadWorld(s, run);
  return mlcp::bullet::loadWorld(s, run,
                                 engine == "bullet" ? Coordinates::Maximal : Coordinates::Reduced);
}

std::string stockOf(const std::string& engine) {
  return engine == "ode" ? "ode-world" : "bullet-si";
}

const char* const kEngines[] = {"bullet", "bullet-multibody", "ode"};

TEST(Articulations, LoadWithTheSameMassesLinksAndJointsInEveryEngine) {
  for (const char* name : kArticulated) {
    SCOPED_TRACE(name);
    const Scene s = load(name);
    ASSERT_FALSE(s.articulations.empty());
    RunSettings run = RunSettings::fromScene(s);
    auto reduced = mlcp::bullet::buildWorld(s, run, Coordinates::Reduced);
    auto maximal = mlcp::bullet::buildWorld(s, run, Coordinates::Maximal);
    auto ode = mlcp::ode::buildWorld(s, run);
    ASSERT_EQ(reduced->multiBodies().size(), s.articulations.size());
    int constraints = 0;
    for (std::size_t a = 0; a < s.articulations.size(); ++a) {
      const auto& art = s.articulations[a];
      const btMultiBody& mb = *reduced->multiBodies()[a];
      EXPECT_EQ(mb.getNumLinks(), int(art.links.size()));
      EXPECT_EQ(mb.hasFixedBase(), art.fixedBase);
      EXPECT_EQ(mb.getBaseMass(), s.bodies[art.base].mass);
      for (std::size_t k = 0; k < art.links.size(); ++k) {
        const double m = s.bodies[art.links[k].body].mass;
        EXPECT_EQ(mb.getLinkMass(int(k)), m);
        EXPECT_DOUBLE_EQ(1 / maximal->bodies()[art.links[k].body]->getInvMass(), m);
        dMass dm;
        dBodyGetMass(ode->bodies()[art.links[k].body], &dm);
        EXPECT_DOUBLE_EQ(dm.mass, m);
        const auto& j = s.joints[art.links[k].joint];
        constraints += j.limits.enabled + j.motor.enabled;
        // ODE: the joint to its parent and one to each child (no contacts before a step).
        const auto children = std::count_if(art.links.begin(), art.links.end(),
                                            [&](const auto& l) { return l.parent == int(k); });
        EXPECT_EQ(dBodyGetNumJoints(ode->bodies()[art.links[k].body]), 1 + children);
      }
    }
    // Maximal: one constraint per joint; reduced: the joints are the tree, limits and motors rows.
    EXPECT_EQ(maximal->world().getNumConstraints(), int(s.joints.size()));
    auto& mw = static_cast<btMultiBodyDynamicsWorld&>(reduced->world());
    EXPECT_EQ(mw.getNumMultiBodyConstraints(), constraints);
    EXPECT_EQ(reduced->world().getNumConstraints(), 0);
  }
}

TEST(Articulations, StartPosesAgreeAcrossEnginesTo1e9) {
  for (const char* name : kArticulated) {
    SCOPED_TRACE(name);
    const Scene s = load(name);
    std::vector<std::vector<BodyState>> states;
    for (const char* e : kEngines) states.push_back(makeWorld(e, s, stockOf(e))->states());
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      if (s.bodies[i].shape.type == mlcp::scene::ShapeType::Plane) continue;
      for (std::size_t e = 1; e < states.size(); ++e) {
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(states[e][i].position[c], states[0][i].position[c], 1e-9)
              << kEngines[e] << " " << s.bodies[i].name;
        // q and -q are one rotation.
        const Quat &a = states[0][i].orientation, &b = states[e][i].orientation;
        const double dot = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
        EXPECT_NEAR(std::abs(dot), 1, 1e-9) << kEngines[e] << " " << s.bodies[i].name;
      }
    }
  }
}

// One articulation around `links` and `base`, the rest of a valid scene around it.
std::string sceneWith(const std::string& links, const std::string& base = "") {
  return R"({"format": "mlcp-scene/1", "bodies": [{"name": "ground", "shape": {"type": "plane"}}],
    "articulations": [{"name": "arm", "fixed_base": true,
      "base": {"shape": {"type": "box", "size": [0.2, 0.2, 0.2]}, "position": [0, 0, 1])" +
         base + R"(}, "links": [)" + links + "]}]}";
}

std::string link(const std::string& name, const std::string& parent, const std::string& joint) {
  return R"({"name": ")" + name + R"(", "parent": )" + parent +
         R"(, "shape": {"type": "box", "size": [0.1, 0.1, 0.3]}, "mass": 1,
            "position": [0, 0, 0.7], "joint": )" +
         joint + "}";
}

const std::string kHinge = R"({"type": "revolute", "anchor": [0, 0, 0.9], "axis": [0, 1, 0]})";

std::string errorOf(const std::string& text) {
  try {
    mlcp::scene::parseScene(text, "bad.json");
  } catch (const mlcp::scene::FormatError& e) {
    return e.what();
  }
  return "";
}

TEST(Articulations, BadArticulationsAreRefusedInOneLine) {
  EXPECT_EQ(errorOf(sceneWith(link("a", "\"arm\"", kHinge))), "");
  const std::pair<std::string, std::string> cases[] = {
      {sceneWith(link("a", "3", kHinge)), "bad parent index 3"},
      {sceneWith(link("a", "\"b\"", kHinge) + "," + link("b", "\"a\"", kHinge)),
       "the parents form a cycle"},
      {sceneWith(link("a", "\"a\"", kHinge)), "a link cannot be its own parent"},
      {sceneWith(link("a", "\"nobody\"", kHinge)), "no link named \"nobody\""},
      {sceneWith(link("a", "-1", R"({"type": "revolute", "anchor": [0, 0, 0.9],
          "axis": [0, 1, 0], "limits": {"lower": 0.5, "upper": -0.5}})")),
       "lower (0.5) is above upper (-0.5)"},
      {sceneWith(link("a", "-1", R"({"type": "screw", "anchor": [0, 0, 0.9]})")),
       "unknown joint type \"screw\" (known: revolute, prismatic, spherical, fixed)"},
      {sceneWith(link("a", "-1", R"({"type": "spherical", "anchor": [0, 0, 0.9],
          "motor": {"velocity": 1, "max_force": 1}})")),
       "takes no limits or motor"},
      {sceneWith(link("a", "-1", R"({"type": "revolute", "anchor": [0, 0, 1e999],
          "axis": [0, 1, 0]})")),
       "not valid JSON"},
      {sceneWith(link("a", "-1", R"({"type": "revolute", "anchor": [0, 0, 0.9],
          "axis": [0, 0, 0]})")),
       "expected a direction"},
      {sceneWith(link("a", "-1", kHinge), R"(, "mass": 3)"), "a fixed base is static"},
      {sceneWith(link("arm", "-1", kHinge)), "link name \"arm\" is used twice"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string message = errorOf(text);
    EXPECT_NE(message.find(expected), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind("bad.json: ", 0), 0u) << message;
  }
  // A joint of the file on an articulation's body would close a loop.
  std::string loop = sceneWith(link("a", "-1", kHinge));
  loop.insert(loop.size() - 1,
              R"(, "joints": [{"type": "ball", "bodies": ["a"], "anchor": [0, 0, 0.5]}])");
  EXPECT_NE(errorOf(loop).find("belongs to articulation \"arm\""), std::string::npos)
      << errorOf(loop);
}

TEST(Articulations, LinksAreStoredParentFirstWhateverTheFileOrder) {
  // The file lists b before its parent a; c names a by its index.
  const Scene s =
      mlcp::scene::parseScene(sceneWith(link("b", "\"a\"", kHinge) + "," + link("a", "-1", kHinge) +
                                        "," + link("c", "1", kHinge)),
                              "order.json");
  ASSERT_EQ(s.articulations.size(), 1u);
  const auto& art = s.articulations[0];
  ASSERT_EQ(art.links.size(), 3u);
  const char* names[] = {"a", "b", "c"};
  const int parents[] = {-1, 0, 0};
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& l = art.links[k];
    EXPECT_EQ(s.bodies[l.body].name, names[k]);
    EXPECT_EQ(l.parent, parents[k]);
    // Joints hold [link, parent], or [link] on the fixed base (a static body: the world).
    EXPECT_EQ(s.joints[l.joint].body0, l.body);
    EXPECT_EQ(s.joints[l.joint].body1, l.parent < 0 ? -1 : art.links[l.parent].body);
  }
  EXPECT_TRUE(s.bodies[art.base].isStatic());
}

// A core solver goes into the multibody world by mlcp::bullet::install (the loader's one call)
// and answers every island of limit_chain; a solver the world cannot take is refused by name.
TEST(Articulations, CoreSolversRunInAMultiBodyWorld) {
  const Scene s = load("limit_chain");
  auto w = makeWorld("bullet-multibody", s, "auto");
  for (int i = 0; i < 60; ++i) {
    w->step();
    EXPECT_EQ(w->last().status, "converged") << "step " << i;
    EXPECT_LE(w->last().residual, 1e-6) << "step " << i;
  }
  EXPECT_THROW(makeWorld("bullet-multibody", s, "bullet-nncg"), std::invalid_argument);
}

// The multibody world runs the core solver named, not the adapter's default (a regression: the
// loader once built its ConstraintSolver without the name, so every name ran auto).
TEST(Articulations, MultiBodyWorldRunsTheSolverNamed) {
  const Scene s = load("arm_push");
  for (const char* solver : {"pgs", "dantzig", "lemke"}) {
    auto w = makeWorld("bullet-multibody", s, solver);
    w->step();
    EXPECT_EQ(w->last().choice.rfind(std::string(solver) + ":", 0), 0u)
        << solver << " ran as " << w->last().choice;
  }
}

// Without articulations a btMultiBodyDynamicsWorld holds the same rigid bodies and joints, and
// Bullet's multibody SI solves their rows as its rigid SI does: the ragdoll (hinges, cone-twists,
// contacts) moves the same in bullet-multibody as in bullet.
TEST(Articulations, ScenesWithoutArticulationsRunAsInBullet) {
  const Scene s = load("ragdoll");
  ASSERT_TRUE(s.articulations.empty());
  auto rigid = makeWorld("bullet", s, "bullet-si");
  auto multi = makeWorld("bullet-multibody", s, "bullet-si");
  for (int i = 0; i < 60; ++i) {
    rigid->step();
    multi->step();
  }
  const auto a = rigid->states(), b = multi->states();
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(b[i].position[c], a[i].position[c], 1e-9) << s.bodies[i].name;
      EXPECT_NEAR(b[i].velocity[c], a[i].velocity[c], 1e-9) << s.bodies[i].name;
    }
}

// 120 steps: finite, every body within 10 m of the origin and slower than 20 m/s.
void expectRunsBounded(const std::string& engine, const Scene& s, const std::string& solver) {
  SCOPED_TRACE(engine + " " + solver);
  auto w = makeWorld(engine, s, solver);
  for (int i = 0; i < 120; ++i) w->step();
  const std::vector<BodyState> states = w->states();
  ASSERT_TRUE(mlcp::scene::isFinite(states));
  for (std::size_t i = 0; i < states.size(); ++i) {
    const auto& p = states[i].position;
    EXPECT_LT(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), 10) << s.bodies[i].name;
  }
  EXPECT_LT(w->last().maxSpeed, 20);
}

TEST(Articulations, EveryArticulatedSceneRunsInEveryEngine) {
  for (const char* name : kArticulated) {
    SCOPED_TRACE(name);
    const Scene s = load(name);
    for (const char* e : kEngines) {
      expectRunsBounded(e, s, stockOf(e));
      expectRunsBounded(e, s, "auto");
    }
  }
}

// The hinge angle of the joint's body0 relative to body1 (or the world), 0 at the start.
double hingeAngle(const Scene& s, const std::vector<BodyState>& states,
                  const mlcp::scene::Joint& j) {
  using mlcp::scene::relative;
  const auto turned = [&](int b) {  // the body's rotation since the start
    return b < 0 ? Quat{} : relative(states[b].orientation, s.bodies[b].orientation);
  };
  const Quat p = turned(j.body1), c = turned(j.body0);
  // p^-1 c: the child's turn in the parent's start frame, about the axis at the start.
  const Quat rel = relative(Quat{p.w, -p.x, -p.y, -p.z}, Quat{c.w, -c.x, -c.y, -c.z});
  return mlcp::scene::twistAngle(rel, j.axis);
}

double worstViolation(const Scene& s, const std::vector<BodyState>& states) {
  double worst = 0;
  for (const auto& j : s.joints)
    if (j.limits.enabled) {
      const double q = hingeAngle(s, states, j);
      worst = std::max({worst, q - j.limits.upper, j.limits.lower - q});
    }
  return worst;
}

// The prismatic offset of the joint's body0 relative to body1 along the axis, 0 at the start.
double sliderOffset(const Scene& s, const std::vector<BodyState>& states,
                    const mlcp::scene::Joint& j) {
  const auto& c = states[j.body0];
  const auto& p = states[j.body1];
  const Quat turned = mlcp::scene::relative(p.orientation, s.bodies[j.body1].orientation);
  const mlcp::scene::Vec3 d{c.position[0] - p.position[0], c.position[1] - p.position[1],
                            c.position[2] - p.position[2]};
  const auto now = mlcp::scene::rotate(Quat{turned.w, -turned.x, -turned.y, -turned.z}, d);
  double offset = 0;
  for (int k = 0; k < 3; ++k)
    offset +=
        j.axis[k] * (now[k] - (s.bodies[j.body0].position[k] - s.bodies[j.body1].position[k]));
  return offset;
}

// arm_push's turret motor (+1 rad/s) turns the arm into its upper limit of 1 rad and the wrist's
// (-0.1 m/s) pushes the paddle into its lower limit of -0.02 m, with the same signs in reduced
// and maximal coordinates.
TEST(Articulations, MotorsDriveIntoTheSameLimitsInEveryEngine) {
  const Scene s = load("arm_push");
  const auto& turret = s.joints[s.articulations[0].links[0].joint];
  const auto& wrist = s.joints[s.articulations[0].links[3].joint];
  ASSERT_EQ(turret.type, mlcp::scene::JointType::Hinge);
  ASSERT_EQ(wrist.type, mlcp::scene::JointType::Slider);
  for (const char* e : kEngines) {
    auto w = makeWorld(e, s, "auto");
    for (int i = 0; i < 120; ++i) w->step();
    const auto states = w->states();
    EXPECT_NEAR(hingeAngle(s, states, turret), 1.0, 0.02) << e;
    EXPECT_NEAR(sliderOffset(s, states, wrist), -0.02, 0.005) << e;
    std::cout << "arm_push " << e << ": turret " << hingeAngle(s, states, turret) << " rad, wrist "
              << sliderOffset(s, states, wrist) << " m\n";
  }
}

// limit_chain after 300 steps (5 s): the joints at their limits, the chain on the ground. Bullet
// with split impulse on (its default) and off; ODE's dWorldStep. Printed for docs/benchmarks.md;
// every engine must keep the chain within a loose 0.6 rad of its limits.
TEST(Articulations, LimitChainViolationAfterSettling) {
  const Scene s = load("limit_chain");
  const RunSettings run = RunSettings::fromScene(s);
  const double h = s.settings.timeStep;
  for (Coordinates c : {Coordinates::Maximal, Coordinates::Reduced})
    for (int split : {1, 0}) {
      auto built = mlcp::bullet::buildWorld(s, run, c);
      built->world().getSolverInfo().m_splitImpulse = split;
      for (int i = 0; i < 300; ++i) built->world().stepSimulation(h, 0, h);
      const double v = worstViolation(s, built->states());
      std::cout << "limit_chain " << (c == Coordinates::Maximal ? "bullet" : "bullet-multibody")
                << " SI split impulse " << (split ? "on" : "off") << ": violation " << v
                << " rad\n";
      EXPECT_LT(v, 0.6);
    }
  // Through the loaders (Bullet's default split impulse): ODE's own, the core solvers (in the
  // multibody world with the drop-in's default position correction), Bullet's multibody MLCP path.
  const std::pair<const char*, const char*> runs[] = {{"ode", "ode-world"},
                                                      {"bullet", "auto"},
                                                      {"ode", "auto"},
                                                      {"bullet", "dantzig"},
                                                      {"ode", "dantzig"},
                                                      {"bullet-multibody", "bullet-mlcp-dantzig"},
                                                      {"bullet-multibody", "auto"},
                                                      {"bullet-multibody", "dantzig"}};
  for (const auto& [engine, solver] : runs) {
    auto w = makeWorld(engine, s, solver);
    for (int i = 0; i < 300; ++i) w->step();
    const double v = worstViolation(s, w->states());
    std::cout << "limit_chain " << engine << " " << solver << ": violation " << v << " rad\n";
    EXPECT_LT(v, 0.6) << engine << " " << solver;
  }
}

}  // namespace
