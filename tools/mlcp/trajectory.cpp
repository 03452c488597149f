#include "trajectory.hpp"

#include <cmath>
#include <fstream>
#include <ostream>
#include <sstream>

#include "csv_rows.hpp"
#include "mlcp/input_limits.hpp"

namespace mlcp::cli {

const char* const kTrajectoryCsvHeader = "scene,engine,solver,step,body,x,y,z,qw,qx,qy,qz";

void writeTrajectoryCsv(std::ostream& out, const scene::World& world, const std::string& solver,
                        int step) {
  const scene::Scene& s = world.scene();
  const std::vector<scene::BodyState> states = world.states();
  writeWholeRows(out, [&](std::ostream& rows) {  // a step's rows together: diff needs them all
    for (std::size_t i = 0; i < states.size(); ++i) {
      if (s.bodies[i].isStatic()) continue;
      const scene::BodyState& b = states[i];
      rows << s.name << ',' << world.engine() << ',' << solver << ',' << step << ','
           << s.bodies[i].name << ',' << b.position[0] << ',' << b.position[1] << ','
           << b.position[2] << ',' << b.orientation.w << ',' << b.orientation.x << ','
           << b.orientation.y << ',' << b.orientation.z << "\n";
    }
  });
}

void Trajectory::record(const scene::World& world, int step) {
  const scene::Scene& s = world.scene();
  const std::vector<scene::BodyState> states = world.states();
  const bool first = steps.empty();
  std::vector<Pose> row;
  for (std::size_t i = 0; i < states.size(); ++i) {
    if (s.bodies[i].isStatic()) continue;
    if (first) bodies.push_back(s.bodies[i].name);
    row.push_back({states[i].position, states[i].orientation});
  }
  steps.push_back(step);
  lines.push_back(0);
  poses.push_back(std::move(row));
}

namespace {

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream s(line);
  std::string f;
  while (std::getline(s, f, ',')) fields.push_back(f);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// The file and line being read, for errors that name both.
struct CsvPlace {
  const std::string& path;
  int line = 0;

  [[noreturn]] void fail(const std::string& what) const {
    throw scene::FormatError(path + ": line " + std::to_string(line) + ": " + what);
  }
};

// Reads the next line without its '\r'; false at the end of the file.
bool nextLine(std::istream& in, std::string& line, CsvPlace& at) {
  if (!std::getline(in, line)) return false;
  ++at.line;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

// Columns 6-12 (x, y, z, qw, qx, qy, qz): finite numbers, the quaternion of unit length.
Pose parsePose(const std::vector<std::string>& f, const CsvPlace& at) {
  double v[7];
  for (int k = 0; k < 7; ++k) {
    std::size_t used = 0;
    try {
      v[k] = std::stod(f[5 + k], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != f[5 + k].size())
      at.fail("column " + std::to_string(6 + k) + ": not a number: '" + io::capped(f[5 + k]) + "'");
    if (!std::isfinite(v[k]))
      at.fail("column " + std::to_string(6 + k) + ": not finite: '" + io::capped(f[5 + k]) + "'");
  }
  // Engines keep orientations unit length; anything far from it was not written by a run.
  if (std::abs(std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]) - 1) > 1e-3)
    at.fail("columns 9-12: the quaternion (qw, qx, qy, qz) is not of length 1");
  return {{v[0], v[1], v[2]}, {v[3], v[4], v[5], v[6]}};
}

int parseStep(const std::string& field, const CsvPlace& at) {
  int step = 0;
  try {
    std::size_t used = 0;
    step = std::stoi(field, &used);
    if (used != field.size() || step < 0) throw std::invalid_argument("step");
  } catch (const std::exception&) {
    at.fail("step: not a step index: '" + io::capped(field) + "'");
  }
  return step;
}

void checkStepComplete(const Trajectory& t, std::size_t bodyInStep, const CsvPlace& at) {
  if (bodyInStep != t.bodies.size())
    at.fail("step " + std::to_string(t.steps.back()) + " (from line " +
            std::to_string(t.lines.back()) + ") has " + std::to_string(bodyInStep) +
            " bodies, the first step " + std::to_string(t.bodies.size()));
}

// Opens a new step when the row's step differs from the last: steps increase, and the step
// before lists every body.
void beginStepIfNew(Trajectory& t, int step, std::size_t& bodyInStep, const CsvPlace& at) {
  if (!t.steps.empty() && step == t.steps.back()) return;
  if (!t.steps.empty() && step < t.steps.back())
    at.fail("step " + std::to_string(step) + " after step " + std::to_string(t.steps.back()) +
            " (steps must increase)");
  if (!t.steps.empty()) checkStepComplete(t, bodyInStep, at);
  t.steps.push_back(step);
  t.lines.push_back(at.line);
  t.poses.emplace_back();
  bodyInStep = 0;
}

// The first step names the bodies (each once); every later step lists them in that order.
void checkBody(Trajectory& t, const std::string& body, std::size_t bodyInStep, const CsvPlace& at) {
  if (t.steps.size() == 1) {
    for (const std::string& b : t.bodies)
      if (b == body)
        at.fail("body '" + io::capped(body) + "' twice in step " + std::to_string(t.steps.back()));
    t.bodies.push_back(body);
  } else if (bodyInStep >= t.bodies.size() || t.bodies[bodyInStep] != body) {
    at.fail("body '" + io::capped(body) + "' where the first step has " +
            (bodyInStep < t.bodies.size() ? "'" + io::capped(t.bodies[bodyInStep]) + "'"
                                          : "no more bodies"));
  }
}

}  // namespace

Trajectory readTrajectoryCsv(const std::string& path) {
  io::checkInputFile(path, io::kMaxTrajectoryFileBytes, "trajectory file");
  std::ifstream in(path);
  if (!in) throw scene::FormatError(path + ": cannot open");
  Trajectory t;
  t.source = path;
  CsvPlace at{path};
  std::string line;
  if (!nextLine(in, line, at)) throw scene::FormatError(path + ": empty file");
  if (line != kTrajectoryCsvHeader)
    at.fail("expected the trajectory header '" + std::string(kTrajectoryCsvHeader) +
            "' (from mlcp run --trajectory), got '" + io::capped(line) + "'");
  std::size_t bodyInStep = 0;
  while (nextLine(in, line, at)) {
    if (line.empty()) continue;
    const std::vector<std::string> f = splitCsv(line);
    if (f.size() != 12) at.fail("expected 12 fields, got " + std::to_string(f.size()));
    const Pose pose = parsePose(f, at);
    beginStepIfNew(t, parseStep(f[3], at), bodyInStep, at);
    checkBody(t, f[4], bodyInStep, at);
    ++bodyInStep;
    t.poses.back().push_back(pose);
  }
  if (t.steps.empty()) throw scene::FormatError(path + ": no data rows");
  if (bodyInStep != t.bodies.size())
    at.fail("the last step " + std::to_string(t.steps.back()) + " has " +
            std::to_string(bodyInStep) + " bodies, the first step " +
            std::to_string(t.bodies.size()));
  return t;
}

double positionDeviation(const Pose& a, const Pose& b) {
  return std::hypot(a.position[0] - b.position[0], a.position[1] - b.position[1],
                    a.position[2] - b.position[2]);
}

double orientationDeviation(const Pose& a, const Pose& b) {
  // As 4-vectors, unit quaternions at an angle phi apart rotate by theta = 2 phi relative to
  // each other, and phi = 2 atan2(|a - b|, |a + b|): exact 0 for equal inputs and accurate for
  // small angles (unlike acos of the dot product). b is flipped to a's half-space first.
  const scene::Quat& p = a.orientation;
  scene::Quat q = b.orientation;
  if (p.w * q.w + p.x * q.x + p.y * q.y + p.z * q.z < 0) q = {-q.w, -q.x, -q.y, -q.z};
  const double minus = std::sqrt((p.w - q.w) * (p.w - q.w) + (p.x - q.x) * (p.x - q.x) +
                                 (p.y - q.y) * (p.y - q.y) + (p.z - q.z) * (p.z - q.z));
  const double plus = std::sqrt((p.w + q.w) * (p.w + q.w) + (p.x + q.x) * (p.x + q.x) +
                                (p.y + q.y) * (p.y + q.y) + (p.z + q.z) * (p.z + q.z));
  return 4 * std::atan2(minus, plus);
}

}  // namespace mlcp::cli
