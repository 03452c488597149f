// Private to mlcp::ode: the island stepper's state and stages (see mlcp/ode/stepper.hpp for the
// pipeline and the conventions).
#pragma once

#include <array>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "mlcp/island/row_solver.hpp"
#include "mlcp/ode/stepper.hpp"
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

// The last step's lambda, to warm-start this step's. Storage reused across steps (no allocation
// once grown): entries in store order and an open-addressing table built once per step, at
// endStep. Joints other than contacts are keyed by the joint; contacts, which are new joints
// every step, by body pair, then by position: a contact takes the answer of the pair's last-step
// contact nearest to it (a chain through the pair's entries, a few per pair), within the match
// distance: ODE's box-box collider orders a face's points differently from step to step, so a
// contact's rank among the pair's is no match (docs/decisions.md, "Adapters: warm starts and
// rows").
class WarmStartCache {
 public:
  // Fills lambda (size m) for the joint and returns true when a matching entry exists.
  bool lookup(dxJoint* joint, int m, double* lambda, double matchDistance);
  void store(dxJoint* joint, int m, const double* lambda);
  // Makes what was stored since the last call the cache that lookup reads.
  void endStep();
  void clear();

 private:
  struct Key {
    std::uintptr_t a = 0, b = 0;  // the joint and 0, or a contact's two bodies
    bool contact = false;
    bool operator==(const Key& o) const { return a == o.a && b == o.b && contact == o.contact; }
  };
  struct Entry {
    Key key;
    int type = 0, m = 0;
    dxBody *body0 = nullptr, *body1 = nullptr;
    int next = -1;  // the pair's next contact in store order
    int last = -1;  // on a pair's first entry: its last entry (while the table is built)
    std::array<double, 3> pos{};  // contacts
    std::array<double, 6> lambda{};
  };
  static Key keyOf(dxJoint* joint);
  int find(const Key& key) const;  // first entry of the key in entries_, -1 if none
  // The entry of the pair's chain from first with m rows nearest to pos (-1 if none), and its
  // squared distance.
  int nearestContact(int first, const dReal* pos, int m, double& d2) const;

  std::vector<Entry> entries_, next_;  // read (last step's) / this step's stores
  std::vector<int> table_;             // entries_ index per slot, -1 empty; size a power of 2
};

struct JointRows {
  dxJoint* joint;
  int m, nub, offset;
};

// Per-island workspace, reused across islands and steps.
struct IslandWork {
  std::vector<JointRows> joints;  // active joints, ordered by class
  std::vector<JointRows> active;  // active joints in island order
  RowSystem rows;
  std::vector<Vector6> bodyTmp;  // per body: M^-1 f_ext + v/h, later J^T lambda
  Vector x, x0, xAlt;
  // ODE's dense layout for dxSolveLCP: A (m x dPAD(m)), (b, x) and (lo, hi) pairs, findex.
  std::vector<double> odeA, odeBx, odeLh;
  std::vector<int> odeFindex;
  Problem odeProblem;  // A assembled for dxSolveLCP, reused like RowSolver's
  RowSystem::AssembleScratch odeScratch;
  Vector odeSlack;
};

}  // namespace mlcp::ode

struct mlcp::ode::Stepper::Impl {
  std::string name;
  Settings options;
  // This step's options of the primary (and reference): options.options, with the world's
  // QuickStep count and factor for pgs/gs under engineIterations (beginStep).
  Options stepOptions;
  Method primary, reference;
  bool hasReference = false;
  // This step's statistics: stats.islands[0 .. islandsUsed) are this step's islands; the
  // entries after them are last steps', reused (nextIslandStats) so that an island's statistics
  // allocate nothing in steady state, and dropped at the end of the step.
  StepStats stats;
  size_t islandsUsed = 0;
  WarmStartCache warm;
  IslandWork work;
  // Settings::keepProblems: this step's islands, and last step's entries whose buffers
  // the island workspace takes in turn.
  std::vector<IslandProblem> problems, spareProblems;
  std::mutex mutex;  // islands may run on ODE's worker threads
  // The first exception an island's solve threw this step: kept by stepIsland and rethrown by
  // Stepper::step once ODE's island processing has returned, so that it never unwinds through
  // ODE's frames (they would leak their job records and leave its threading state half-done).
  std::exception_ptr pendingError;

  // dstepper_fn_t and dmemestimate_fn_t: they find the Impl of the world being stepped.
  static void stepIsland(const dxStepperProcessingCallContext* context);
  static sizeint estimateMemory(dxBody* const* body, unsigned nb, dxJoint* const* joint,
                                unsigned nj);
  static unsigned estimateMaxCallCount(unsigned activeThreads, unsigned allowedThreads);

  // The next island's statistics, reset to IslandStats{}.
  IslandStats& nextIslandStats();
  // The step's options from the settings and the world (engineIterations).
  void beginStep(dxWorld* world);
  // One island through the stages of mlcp/ode/stepper.hpp, its statistics appended to stats.
  void runIsland(const dxStepperProcessingCallContext* context);
  // runIsland's parts: ODE's own step on the whole island (ode-step, ode-quickstep); stage 4
  // into work.x0 (returns whether any joint matched); stage 5 into work.x; the reference
  // method's solve into work.xAlt and its distance from work.x.
  void forwardIsland(const dxStepperProcessingCallContext* context, IslandStats& st);
  bool warmStartIsland(IslandWork& w);
  void solveIsland(const dxStepperProcessingCallContext* context, int nub, IslandStats& st);
  void compareWithReference(const dxStepperProcessingCallContext* context, int nub,
                            std::uint64_t key, IslandStats& st);
  // Swaps the island's rows and answer into a kept IslandProblem (after integration).
  void keepProblem(IslandWork& w, int island);
  sizeint memoryFor(dxBody* const* body, unsigned nb, dxJoint* const* joint, unsigned nj) const;
};
