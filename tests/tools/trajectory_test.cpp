// Trajectory files of `mlcp run --trajectory` and the deviations `mlcp diff` reports
// (tools/mlcp/trajectory.hpp).
#include "trajectory.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

namespace mlcp::cli {
namespace {

TEST(Deviation, PositionIsTheDistance) {
  Pose a, b;
  a.position = {1, 2, 3};
  b.position = {1, 5, 7};
  EXPECT_DOUBLE_EQ(positionDeviation(a, b), 5);
  EXPECT_DOUBLE_EQ(positionDeviation(a, a), 0);
}

TEST(Deviation, OrientationIsTheAngleBetween) {
  Pose a, b;
  a.orientation = scene::fromAxisAngle({0, 0, 1}, 0.3);
  b.orientation = scene::fromAxisAngle({0, 0, 1}, -0.2);
  EXPECT_NEAR(orientationDeviation(a, b), 0.5, 1e-12);
  b.orientation = scene::fromAxisAngle({1, 1, 0}, 0.3);
  // a then b^-1 about different axes: the angle of the relative rotation, symmetric.
  EXPECT_NEAR(orientationDeviation(a, b), orientationDeviation(b, a), 1e-12);
  // q and -q are one rotation.
  scene::Quat q = a.orientation;
  b.orientation = {-q.w, -q.x, -q.y, -q.z};
  EXPECT_NEAR(orientationDeviation(a, b), 0, 1e-12);
  // The largest deviation is pi.
  b.orientation = scene::fromAxisAngle({0, 0, 1}, 0.3 + M_PI);
  EXPECT_NEAR(orientationDeviation(a, b), M_PI, 1e-9);
}

class TrajectoryFile : public ::testing::Test {
 protected:
  std::string write(const std::string& text) {
    // A file of this test's own: ctest runs the tests of this suite in parallel processes, and
    // one shared name let one test's TearDown remove or overwrite another's file (a red CI run).
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = ::testing::TempDir() + "trajectory_test_" + test->name() + "_" +
            std::to_string(::getpid()) + ".csv";
    std::ofstream(path_) << text;
    return path_;
  }
  void TearDown() override { std::remove(path_.c_str()); }
  std::string error(const std::string& text) {
    try {
      readTrajectoryCsv(write(text));
    } catch (const scene::FormatError& e) {
      return e.what();
    }
    return "no error";
  }
  std::string path_;
};

const std::string kHeader = std::string(kTrajectoryCsvHeader) + "\n";

TEST_F(TrajectoryFile, ReadsStepsAndBodies) {
  const Trajectory t = readTrajectoryCsv(write(kHeader + "s,ode,pgs,0,a,0,0,1,1,0,0,0\n"
                                                         "s,ode,pgs,0,b,0,0,2,1,0,0,0\n"
                                                         "s,ode,pgs,1,a,0,0,0.5,0,1,0,0\n"
                                                         "s,ode,pgs,1,b,0,0,1.5,1,0,0,0\n"));
  ASSERT_EQ(t.steps, (std::vector<int>{0, 1}));
  ASSERT_EQ(t.bodies, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(t.lines, (std::vector<int>{2, 4}));
  EXPECT_DOUBLE_EQ(t.poses[1][0].position[2], 0.5);
  EXPECT_DOUBLE_EQ(t.poses[1][0].orientation.x, 1);
}

TEST_F(TrajectoryFile, ErrorsNameFileAndLine) {
  const std::string ok = "s,ode,pgs,0,a,0,0,1,1,0,0,0\n";
  EXPECT_NE(error("step,body\n").find(": line 1: expected the trajectory header"),
            std::string::npos);
  EXPECT_NE(error(kHeader).find(": no data rows"), std::string::npos);
  EXPECT_NE(error(kHeader + ok + "s,ode,pgs,1,a,0,0\n").find(": line 3: expected 12 fields"),
            std::string::npos);
  EXPECT_NE(error(kHeader + "s,ode,pgs,0,a,0,zero,1,1,0,0,0\n")
                .find(": line 2: column 7: not a number: 'zero'"),
            std::string::npos);
  EXPECT_NE(
      error(kHeader + "s,ode,pgs,0,a,0,nan,1,1,0,0,0\n").find(": line 2: column 7: not finite"),
      std::string::npos);
  EXPECT_NE(error(kHeader + "s,ode,pgs,0,a,0,0,1,2,0,0,0\n")
                .find("quaternion (qw, qx, qy, qz) is not of length 1"),
            std::string::npos);
  try {
    readTrajectoryCsv("/dev/zero");
    ADD_FAILURE() << "/dev/zero read";
  } catch (const scene::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/zero: not a regular file"), std::string::npos);
  }
  EXPECT_LT(
      error(kHeader + "s,ode,pgs,0,a,0," + std::string(1 << 20, '7') + "x,1,1,0,0,0\n").size(),
      300u);
  EXPECT_NE(error(kHeader + ok + "s,ode,pgs,1,b,0,0,1,1,0,0,0\n")
                .find(": line 3: body 'b' where the first step has 'a'"),
            std::string::npos);
  EXPECT_NE(error(kHeader + "s,ode,pgs,1,a,0,0,1,1,0,0,0\n" + ok).find(": line 3: step 0 after"),
            std::string::npos);
  EXPECT_NE(error(kHeader + ok + "s,ode,pgs,0,b,0,0,1,1,0,0,0\ns,ode,pgs,1,a,0,0,1,1,0,0,0\n")
                .find("the last step 1 has 1 bodies, the first step 2"),
            std::string::npos);
  EXPECT_NE(error(kHeader + ok).find("no error"), std::string::npos);
}

}  // namespace
}  // namespace mlcp::cli
