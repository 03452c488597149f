// The scene limits (mlcp/scene/scene_limits.hpp) and the scene files that once crashed the
// loader or an engine (tests/data/fuzz/scene_*): each is now a FormatError of one short line
// naming the file and the field.
#include "mlcp/scene/scene_limits.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mlcp/scene/scene.hpp"

namespace {

using namespace mlcp::scene;

const std::string kFuzzData = std::string(MLCP_SOURCE_DIR) + "/tests/data/fuzz/";

std::string errorOf(const std::string& text, const std::string& source = "lim.json") {
  try {
    parseScene(text, source);
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

void expectFileError(const std::string& name, const std::vector<std::string>& parts) {
  const std::string path = kFuzzData + name;
  std::string what;
  try {
    loadScene(path);
  } catch (const FormatError& e) {
    what = e.what();
  }
  EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
  for (const std::string& p : parts) EXPECT_NE(what.find(p), std::string::npos) << what;
  EXPECT_LE(what.size(), path.size() + 200) << what.substr(0, 400);
  EXPECT_EQ(what.find('\n'), std::string::npos) << what.substr(0, 400);
}

std::string oneBody(const std::string& fields) {
  return R"({"format": "mlcp-scene/1", "bodies": [{"name": "b", )" + fields + "}]}";
}
const char* kBox = R"("shape": {"type": "box", "size": [1, 1, 1]}, )";

TEST(SceneFuzzRegression, NumberOverflow1e309) {
  expectFileError("scene_number_overflow_1e309.json", {"not valid JSON: number overflow"});
}

TEST(SceneFuzzRegression, BoxSize1e308) {
  expectFileError("scene_box_size_1e308.json",
                  {"body \"box\": shape.size: 1e+300 is outside [0.0001, 1e+04] m"});
}

TEST(SceneFuzzRegression, HingeAxis1e308IsNormalisedNotZeroed) {
  // The axis is a direction: [-1e308, -1, 0] is -x. Its norm overflowed, and the axis became
  // [0, 0, 0], on which ODE aborts.
  const std::string path = kFuzzData + "scene_hinge_axis_1e308.json";
  const Scene s = loadScene(path);
  ASSERT_EQ(s.joints.size(), 1u);
  EXPECT_EQ(s.joints[0].axis, (Vec3{-1, -1e-308, 0}));
}

TEST(SceneFuzzRegression, Nested5000Levels) {
  expectFileError("scene_nested_5000.json", {"JSON nested deeper than 64 levels"});
}

// Found by scene_parser_fuzz: a key of 7000 characters was echoed whole ("unknown field ...").
TEST(SceneFuzzRegression, LongUnknownField) {
  expectFileError("scene_long_unknown_field.json", {"unknown field \"po[[[[", "...\""});
}

// Found by scene_parser_fuzz: a key with an escaped newline ("radi\ns") was echoed with the
// newline, a message of two lines. Echoed keys and names have their control characters escaped.
TEST(SceneFuzzRegression, UnknownFieldWithANewlineIsOneLine) {
  expectFileError("scene_unknown_field_with_newline.json", {"unknown field \"radi\\ns\""});
}

TEST(SceneFuzzRegression, LongNamesAreCappedInEveryMessage) {
  const std::string name(5000, 'n');
  for (const std::string& text :
       {oneBody(std::string(kBox) + R"("mass": 1, "material": ")" + name + "\""),
        R"({"format": "mlcp-scene/1", "materials": {")" + name +
            R"(": {"friction": -1}}, "bodies": []})",
        R"({"format": "mlcp-scene/1", "bodies": [{"name": "b", )" + std::string(kBox) +
            R"("mass": 1}], "joints": [{"type": "ball", "bodies": [")" + name +
            R"("], "anchor": [0, 0, 0]}]})"}) {
    const std::string e = errorOf(text);
    EXPECT_FALSE(e.empty());
    EXPECT_LT(e.size(), 300u) << e.substr(0, 400);
  }
}

TEST(SceneFiles, NotRegularFilesAreRefused) {
  for (const char* path : {"/dev/zero", "/dev/urandom"}) {
    try {
      loadScene(path);
      ADD_FAILURE() << path;
    } catch (const FormatError& e) {
      EXPECT_EQ(std::string(e.what()),
                std::string(path) + ": not a regular file (a scene file must be one)");
    }
  }
}

TEST(SceneLimits, EachRangeNamesItsField) {
  using namespace limits;
  struct Case {
    std::string text, message;
  };
  const std::vector<Case> cases = {
      {oneBody(R"("shape": {"type": "box", "size": [1, 2e4, 1]}, "mass": 1)"),
       "body \"b\": shape.size: 2e+04 is outside [0.0001, 1e+04] m"},
      {oneBody(R"("shape": {"type": "sphere", "radius": 1e-5}, "mass": 1)"),
       "body \"b\": shape.radius: 1e-05 is outside"},
      {oneBody(R"("shape": {"type": "capsule", "radius": 1, "length": 1e5}, "mass": 1)"),
       "body \"b\": shape.length: 1e+05 is outside [0, 1e+04] m"},
      {oneBody(std::string(kBox) + R"("mass": 1e9)"),
       "body \"b\": mass: 1e+09 is outside [0.0001, 1e+08] kg"},
      {oneBody(std::string(kBox) + R"("mass": 1e-5)"), "body \"b\": mass: 1e-05 is outside"},
      {oneBody(std::string(kBox) + R"("mass": 1, "position": [0, -2e5, 0])"),
       "body \"b\": position: -2e+05 is outside [-1e+05, 1e+05] m"},
      {oneBody(std::string(kBox) + R"("mass": 1, "velocity": [0, 0, 1e5])"),
       "body \"b\": velocity: 1e+05 is outside [-1e+04, 1e+04] m/s"},
      {oneBody(std::string(kBox) + R"("mass": 1, "angular_velocity": [1e5, 0, 0])"),
       "body \"b\": angular_velocity: 1e+05 is outside"},
      {R"({"format": "mlcp-scene/1", "gravity": [0, 0, -1e5], "bodies": [{"name": "b", )" +
           std::string(kBox) + R"("mass": 1}]})",
       "scene: gravity: -1e+05 is outside [-1e+04, 1e+04] m/s^2"},
      {R"({"format": "mlcp-scene/1", "settings": {"time_step": 2}, "bodies": [{"name": "b", )" +
           std::string(kBox) + R"("mass": 1}]})",
       "settings: time_step: 2 is outside [1e-06, 1] s"},
      {R"({"format": "mlcp-scene/1", "settings": {"cfm": 5}, "bodies": [{"name": "b", )" +
           std::string(kBox) + R"("mass": 1}]})",
       "settings: cfm: 5 is outside [0, 1]"},
      {R"({"format": "mlcp-scene/1", "settings": {"steps": 20000000}, "bodies": [{"name": "b", )" +
           std::string(kBox) + R"("mass": 1}]})",
       "settings: steps: 2e+07 is outside [1, 1e+07]"},
      {R"({"format": "mlcp-scene/1", "solver": {"tolerance": 1e-20}, "bodies": [{"name": "b", )" +
           std::string(kBox) + R"("mass": 1}]})",
       "solver: tolerance: 1e-20 is outside [1e-16, 1]"},
      {R"({"format": "mlcp-scene/1", "materials": {"glue": {"friction": 1000}}, "bodies": [{"name": "b", )" +
           std::string(kBox) + R"("mass": 1}]})",
       "material \"glue\": friction: 1e+03 is outside [0, 100]"},
      {R"({"format": "mlcp-scene/1", "bodies": [{"name": "b", )" + std::string(kBox) +
           R"("mass": 1}], "joints": [{"type": "hinge", "bodies": ["b"], "anchor": [0, 0, 1e6], "axis": [0, 0, 1]}]})",
       "joint \"joints[0]\": anchor: 1e+06 is outside [-1e+05, 1e+05] m"},
      {R"({"format": "mlcp-scene/1", "bodies": [{"name": "b", )" + std::string(kBox) +
           R"("mass": 1}], "joints": [{"type": "hinge", "bodies": ["b"], "anchor": [0, 0, 0], "axis": [0, 0, 1], "motor": {"velocity": 1, "max_force": 1e11}}]})",
       "joint \"joints[0]\": motor.max_force: 1e+11 is outside [0, 1e+10] N or N m"},
      {R"({"format": "mlcp-scene/1", "bodies": [{"name": "b", )" + std::string(kBox) +
           R"("mass": 1}], "joints": [{"type": "slider", "bodies": ["b"], "axis": [0, 0, 1], "limits": {"lower": -1e6, "upper": 0}}]})",
       "joint \"joints[0]\": limits.lower: -1e+06 is outside"},
      {R"({"format": "mlcp-scene/1", "bodies": [{"generator": "stack", "name": "s", "count": 60, "mass_factor": 2, "body": {)" +
           std::string(kBox) + R"("mass": 1}}]})",
       "body \"s.27\": mass: 1.34e+08 is outside [0.0001, 1e+08] kg"},
  };
  for (const Case& c : cases) {
    const std::string e = errorOf(c.text);
    EXPECT_EQ(e.rfind("lim.json: ", 0), 0u) << e;
    EXPECT_NE(e.find(c.message), std::string::npos)
        << "got '" << e << "', want '" << c.message << "'";
  }
}

TEST(SceneLimits, ValuesAtTheLimitsLoad) {
  using namespace limits;
  const Scene s = parseScene(R"({"format": "mlcp-scene/1", "gravity": [0, 0, -1e4],
    "settings": {"time_step": 1e-6, "steps": 10000000, "cfm": 1},
    "solver": {"tolerance": 1e-16, "iterations": 1000000},
    "materials": {"glue": {"friction": 100}},
    "bodies": [
      {"name": "big", "shape": {"type": "box", "size": [1e4, 1e4, 1e-4]}, "mass": 1e8,
       "position": [1e5, -1e5, 0], "velocity": [1e4, 0, -1e4], "angular_velocity": [0, 1e4, 0]},
      {"name": "small", "shape": {"type": "sphere", "radius": 1e-4}, "mass": 1e-4,
       "material": "glue"},
      {"name": "rod", "shape": {"type": "capsule", "radius": 1e4, "length": 0}, "mass": 1}],
    "joints": [{"type": "hinge", "bodies": ["small"], "anchor": [0, 0, 1e5], "axis": [1e-300, 0, 0],
                "limits": {"lower": -1e5, "upper": 1e5}, "motor": {"velocity": -1e4, "max_force": 1e10}}]})",
                             "edge.json");
  EXPECT_EQ(s.bodies.size(), 3u);
  EXPECT_EQ(s.joints[0].axis, (Vec3{1, 0, 0}));
}

TEST(SceneLimits, EveryShippedSceneIsWithinThem) {
  for (const std::string& f : listSceneFiles(std::string(MLCP_SOURCE_DIR) + "/scenes"))
    EXPECT_NO_THROW(checkSceneLimits(loadScene(f))) << f;
}

}  // namespace
