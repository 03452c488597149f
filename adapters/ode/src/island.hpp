// Private to mlcp::ode: the island stepper's state and stages (see mlcp/ode/stepper.hpp for the
// pipeline and the conventions).
#pragma once

#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "mlcp/ode/stepper.hpp"
#include "mlcp/row_solver.hpp"
#include "mlcp/rows.hpp"
#include "mlcp/solver.hpp"
#include "ode_internal.hpp"

namespace mlcp::ode {

// One way to solve an island problem.
struct Method {
  enum class Kind {
    ForwardStep,       // ODE's dxStepIsland does the whole island
    ForwardQuickStep,  // ODE's dxQuickStepIsland does the whole island
    OdeLcp,            // ODE's dxSolveLCP on our rows
    Core,              // mlcp::RowSolver on our rows (a core solver or "auto", verified)
  };
  Kind kind = Kind::Core;
  std::string name;
  std::unique_ptr<RowSolver> solver;  // Core only

  bool forwards() const { return kind == Kind::ForwardStep || kind == Kind::ForwardQuickStep; }
};

// Throws std::invalid_argument for an unknown name. Core methods get a RowSolver with these
// settings (its solver set to `name`).
Method makeMethod(const std::string& name, RowSolverSettings settings);

// The last step's lambda, to warm-start this step's.
class WarmStartCache {
 public:
  // Fills lambda (size m) for the joint and returns true when a matching entry exists.
  bool lookup(dxJoint* joint, int m, double* lambda, double matchDistance) const;
  void store(dxJoint* joint, int m, const double* lambda);
  // Makes what was stored since the last call the cache that lookup reads.
  void endStep();
  void clear();

 private:
  struct Entry {
    int type = 0, m = 0;
    dxBody *body0 = nullptr, *body1 = nullptr;
    std::array<double, 6> lambda{};
  };
  struct ContactEntry {
    int m = 0;
    std::array<double, 3> pos{};
    std::array<double, 6> lambda{};
  };
  struct PairHash {
    std::size_t operator()(const std::pair<dxBody*, dxBody*>& p) const {
      return std::hash<dxBody*>()(p.first) * 31 + std::hash<dxBody*>()(p.second);
    }
  };
  using JointMap = std::unordered_map<dxJoint*, Entry>;
  using ContactMap =
      std::unordered_map<std::pair<dxBody*, dxBody*>, std::vector<ContactEntry>, PairHash>;
  JointMap joints_[2];
  ContactMap contacts_[2];
  int read_ = 0;  // joints_[read_] is last step's, joints_[1 - read_] this step's
  // Rank of a contact among this step's contacts of its body pair (lookup and store agree).
  mutable std::unordered_map<std::pair<dxBody*, dxBody*>, int, PairHash> lookupRank_, storeRank_;
};

struct JointRows {
  dxJoint* joint;
  int m, nub, offset;
};

// Per-island workspace, reused across islands and steps.
struct IslandWork {
  std::vector<JointRows> joints;
  RowSystem rows;
  std::vector<Vector6> bodyTmp;  // per body: M^-1 f_ext + v/h, later J^T lambda
  Vector x, x0, xAlt;
  // ODE's dense layout for dxSolveLCP: A (m x dPAD(m)), (b, x) and (lo, hi) pairs, findex.
  std::vector<double> odeA, odeBx, odeLh;
  std::vector<int> odeFindex;
};

}  // namespace mlcp::ode

struct mlcp::ode::Stepper::Impl {
  std::string name;
  StepperOptions options;
  Method primary, reference;
  bool hasReference = false;
  StepStats stats;
  WarmStartCache warm;
  IslandWork work;
  std::mutex mutex;  // islands may run on ODE's worker threads

  // dstepper_fn_t and dmemestimate_fn_t: they find the Impl of the world being stepped.
  static void stepIsland(const dxStepperProcessingCallContext* context);
  static sizeint estimateMemory(dxBody* const* body, unsigned nb, dxJoint* const* joint,
                                unsigned nj);
  static unsigned estimateMaxCallCount(unsigned activeThreads, unsigned allowedThreads);

  void runIsland(const dxStepperProcessingCallContext* context);
  sizeint memoryFor(dxBody* const* body, unsigned nb, dxJoint* const* joint, unsigned nj) const;
};
