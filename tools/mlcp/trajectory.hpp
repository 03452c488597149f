// Body trajectories of scene runs: written by `mlcp run --trajectory`, read and compared by
// `mlcp diff`.
//
// The trajectory CSV is tidy, one row per step and dynamic body (static bodies never move):
//   scene,engine,solver,step,body,x,y,z,qw,qx,qy,qz
// step is the 0-based step index of `mlcp run`'s CSV (the state after that step); x, y, z the
// centre of mass (world, m); qw..qz the orientation (unit quaternion, body to world). Within
// a file every step lists the same bodies in the same order, steps in increasing order.
//
// Deviation of two poses of one body: position |p_a - p_b| (m); orientation the angle of the
// rotation taking one to the other (of q_a q_b^-1), in [0, pi] (rad; q and -q are the same
// rotation).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "mlcp/scene/world.hpp"

namespace mlcp::cli {

extern const char* const kTrajectoryCsvHeader;

// Rows for the world's last step (dynamic bodies only); `solver` as in writeStepCsv.
void writeTrajectoryCsv(std::ostream& out, const scene::World& world, const std::string& solver,
                        int step);

struct Pose {
  scene::Vec3 position{0, 0, 0};
  scene::Quat orientation;
};

struct Trajectory {
  std::string source;                    // file name, or "<engine> <solver>" for a run in memory
  std::vector<std::string> bodies;       // dynamic bodies, in the order of every step
  std::vector<int> steps;                // step index of each recorded step
  std::vector<int> lines;                // file line where each step starts (0: not from a file)
  std::vector<std::vector<Pose>> poses;  // [recorded step][body]

  // Appends the world's current state (after a step) as step `step`.
  void record(const scene::World& world, int step);
};

// Reads a trajectory CSV; throws scene::FormatError naming the file and line of what is wrong.
Trajectory readTrajectoryCsv(const std::string& path);

double positionDeviation(const Pose& a, const Pose& b);     // m
double orientationDeviation(const Pose& a, const Pose& b);  // rad, in [0, pi]

}  // namespace mlcp::cli
