// The per-step measures of a scene run as numpy columns named as in `mlcp run`'s CSV (shared by
// mlcp._mlcp.run and sweep_run).
#pragma once

#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>
#include <utility>
#include <vector>

#include "arrays.hpp"
#include "mlcp/scene/world.hpp"

namespace mlcp::python {

struct Columns {
  std::vector<double> solverMs, stepMs, residual, maxPenetration, jointError, energy, momentum,
      maxSpeed;
  std::vector<int> iterations, fallbacks, contacts;
  std::vector<std::string> status, choice;
  // With states recorded, per step and scene body: x y z, w x y z, vx vy vz (flat, C order).
  std::vector<double> positions, orientations, velocities;

  void add(const scene::StepMeasures& m) {
    solverMs.push_back(m.solverMs);
    stepMs.push_back(m.stepMs);
    residual.push_back(m.residual);
    maxPenetration.push_back(m.maxPenetration);
    jointError.push_back(m.jointError);
    energy.push_back(m.energy);
    momentum.push_back(m.momentum);
    maxSpeed.push_back(m.maxSpeed);
    iterations.push_back(m.iterations);
    fallbacks.push_back(m.fallbacks);
    contacts.push_back(m.contacts);
    status.push_back(m.status);
    choice.push_back(m.choice);
  }

  void addStates(const std::vector<scene::BodyState>& bodies) {
    for (const scene::BodyState& b : bodies) {
      positions.insert(positions.end(), b.position.begin(), b.position.end());
      orientations.insert(orientations.end(),
                          {b.orientation.w, b.orientation.x, b.orientation.y, b.orientation.z});
      velocities.insert(velocities.end(), b.velocity.begin(), b.velocity.end());
    }
  }

  // The step columns into `out` (status and choice as lists of str), leaving this empty.
  void moveInto(nb::dict& out) {
    out["solver_ms"] = toNumpy(std::move(solverMs));
    out["step_ms"] = toNumpy(std::move(stepMs));
    out["residual"] = toNumpy(std::move(residual));
    out["iterations"] = toNumpy(std::move(iterations));
    out["status"] = std::move(status);
    out["fallbacks"] = toNumpy(std::move(fallbacks));
    out["choice"] = std::move(choice);
    out["contacts"] = toNumpy(std::move(contacts));
    out["max_penetration"] = toNumpy(std::move(maxPenetration));
    out["joint_error"] = toNumpy(std::move(jointError));
    out["energy"] = toNumpy(std::move(energy));
    out["momentum"] = toNumpy(std::move(momentum));
    out["max_speed"] = toNumpy(std::move(maxSpeed));
  }
};

}  // namespace mlcp::python
