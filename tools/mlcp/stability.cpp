#include "stability.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mlcp::cli {

const char* toString(Outcome outcome) {
  switch (outcome) {
    case Outcome::Stable: return "stable";
    case Outcome::Drifting: return "drifting";
    case Outcome::Collapsed: return "collapsed";
    case Outcome::Exploded: return "exploded";
    case Outcome::SolverFailure: return "solver-failure";
  }
  return "?";
}

namespace {

std::string describe(const char* what, double value, const char* op, double limit,
                     const char* unit) {
  std::ostringstream s;
  s.precision(3);
  s << what << ' ' << value << unit << ' ' << op << ' ' << limit << unit;
  return s.str();
}

}  // namespace

Classification classify(const CellMeasures& m, const StabilityThresholds& t) {
  const int steps = std::max(m.steps, 1);
  const double failed = double(m.failedSteps) / steps, fellBack = double(m.fallbackSteps) / steps;
  if (!m.finite) return {Outcome::Exploded, "non-finite body state"};
  // NaN-safe: a NaN speed is not <= the bound.
  if (!(m.maxSpeed <= t.maxSpeed))
    return {Outcome::Exploded, describe("max speed", m.maxSpeed, ">", t.maxSpeed, " m/s")};
  if (failed > t.failureShare)
    return {Outcome::SolverFailure,
            describe("failed steps", 100 * failed, ">", 100 * t.failureShare, " %")};
  if (fellBack > t.failureShare)
    return {Outcome::SolverFailure,
            describe("fallback steps", 100 * fellBack, ">", 100 * t.failureShare, " %")};
  if (m.maxDisplacementRatio > t.collapseFraction)
    return {Outcome::Collapsed,
            describe("a box moved", m.maxDisplacementRatio, ">", t.collapseFraction, " edge")};
  if (m.maxPenetration > t.collapsePenetration)
    return {Outcome::Collapsed,
            describe("penetration", m.maxPenetration, ">", t.collapsePenetration, " m")};
  if (m.topDisplacement > t.drift)
    return {Outcome::Drifting, describe("top box moved", m.topDisplacement, ">", t.drift, " m")};
  return {Outcome::Stable, describe("top box moved", m.topDisplacement, "<=", t.drift, " m")};
}

scene::Scene stackScene(const std::string& name, int height, double massRatio, double timeStep,
                        double cfm) {
  if (height < 1) throw std::invalid_argument("stack height must be at least 1");
  if (!(massRatio > 0)) throw std::invalid_argument("mass ratio must be positive");
  if (!(timeStep > 0)) throw std::invalid_argument("time step must be positive");
  if (!(cfm >= 0) || !std::isfinite(cfm))
    throw std::invalid_argument("cfm must be finite and >= 0");
  scene::Scene s;
  s.name = name;
  s.source = "<mlcp stability>";
  s.description = "stack of " + std::to_string(height) + " cubes, top/bottom mass ratio " +
                  std::to_string(massRatio);
  s.settings.timeStep = timeStep;
  s.settings.cfm = cfm;
  s.materials.push_back(scene::Material{"default"});
  scene::Body ground;
  ground.name = "ground";
  ground.shape.type = scene::ShapeType::Plane;
  s.bodies.push_back(ground);
  const double factor = height > 1 ? std::pow(massRatio, 1.0 / (height - 1)) : 1.0;
  double mass = 1;
  for (int i = 0; i < height; ++i, mass *= factor) {
    scene::Body box;
    box.name = "box." + std::to_string(i);
    box.shape.type = scene::ShapeType::Box;
    box.shape.size = {1, 1, 1};
    box.mass = mass;
    box.inertia = scene::inertiaOf(box.shape, mass);
    box.position = {0, 0, 0.5 + i};
    s.bodies.push_back(box);
  }
  return s;
}

CellTracker::CellTracker(const scene::Scene& s) : scene_(s) {
  for (int i = 0; i < int(s.bodies.size()); ++i) {
    if (s.bodies[i].isStatic()) continue;
    boxes_.push_back(i);
    start_.push_back(s.bodies[i].position);
  }
}

void CellTracker::observe(const std::vector<scene::BodyState>& states,
                          const scene::StepMeasures& m) {
  ++m_.steps;
  m_.finite = m_.finite && scene::isFinite(states);
  m_.maxSpeed = std::max(m_.maxSpeed, m.maxSpeed);
  if (!std::isfinite(m.maxSpeed)) m_.maxSpeed = m.maxSpeed;
  if (m.status == "failed" || m.status == "numerical-issue" || m.status == "unsupported")
    ++m_.failedSteps;
  if (m.fallbacks > 0) ++m_.fallbackSteps;
  m_.maxPenetration = std::max(m_.maxPenetration, m.maxPenetration);
  for (std::size_t k = 0; k < boxes_.size(); ++k) {
    const scene::Body& body = scene_.bodies[boxes_[k]];
    const scene::Vec3& p = states[boxes_[k]].position;
    const double d = std::hypot(p[0] - start_[k][0], p[1] - start_[k][1], p[2] - start_[k][2]);
    const auto& size = body.shape.size;
    const double edge = body.shape.type == scene::ShapeType::Box
                            ? std::min({size[0], size[1], size[2]})
                            : 2 * body.shape.radius;
    m_.maxDisplacementRatio = std::max(m_.maxDisplacementRatio, d / edge);
    if (k + 1 == boxes_.size()) m_.topDisplacement = std::max(m_.topDisplacement, d);
  }
}

}  // namespace mlcp::cli
