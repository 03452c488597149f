#include "island.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>

#include "mlcp/registry.hpp"
#include "mlcp/residual.hpp"

namespace mlcp::ode {

namespace {

constexpr int kRowWidth = dDA__MAX;  // 6: [linear; angular]

Eigen::Matrix3d toEigen(const dMatrix3 m) {
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = m[r * 4 + c];
  return out;
}

// Stage 1, as dxStepIsland_Stage0_Bodies (same operations in the same order, so that the
// forces and inertias equal stock's to the bit).
void prepareBodies(dxWorld* world, dxBody* const* body, unsigned nb, dReal h, RowSystem& rows) {
  rows.bodies.resize(nb);
  for (unsigned i = 0; i < nb; ++i) body[i]->tag = static_cast<int>(i);
  for (int axis = 0; axis < 3; ++axis) {
    const dReal g = world->gravity[axis];
    if (g == 0) continue;
    for (unsigned i = 0; i < nb; ++i)
      if ((body[i]->flags & dxBodyNoGravity) == 0) body[i]->facc[axis] += body[i]->mass.mass * g;
  }
  for (unsigned i = 0; i < nb; ++i) {
    dxBody* b = body[i];
    dMatrix3 tmp, invI;
    dMultiply2_333(tmp, b->invI, b->posr.R);
    dMultiply0_333(invI, b->posr.R, tmp);
    rows.bodies[i].invMass = b->invMass;
    rows.bodies[i].invInertia = toEigen(invI);
    if ((b->flags & dxBodyGyroscopic) && b->invMass > 0) {
      // The implicit gyroscopic torque (Lacoursiere 2006), as ODE computes it.
      dMatrix3 I;
      dMultiply2_333(tmp, b->mass.I, b->posr.R);
      dMultiply0_333(I, b->posr.R, tmp);
      dVector3 L;
      dMultiply0_331(L, I, b->avel);
      dMatrix3 Itild = {0};
      dSetCrossMatrixMinus(Itild, L, dV3E__MAX);
      for (int k = dM3E__MIN; k != dM3E__MAX; ++k) Itild[k] = Itild[k] * h + I[k];
      dScaleVector3(L, dRecip(h));
      dMatrix3 itInv;
      if (dInvertMatrix3(itInv, Itild) != 0) {
        dMultiply0_333(Itild, I, itInv);
        Itild[dM3E_XX] -= 1;
        Itild[dM3E_YY] -= 1;
        Itild[dM3E_ZZ] -= 1;
        dVector3 tau0;
        dMultiply0_331(tau0, Itild, L);
        for (int k = 0; k < 3; ++k) b->tacc[k] += tau0[k];
      }
    }
  }
}

// 0: all rows unbounded, 1: mixed, 2: no unbounded row.
int jointClass(const JointRows& j) { return j.nub == j.m ? 0 : j.nub > 0 ? 1 : 2; }

// Stage 2: getInfo1 for all joints (before any getInfo2), the active ones ordered unbounded |
// mixed | LCP, island order kept within each class (bucketed through a reused buffer:
// std::stable_partition allocates on every call). Returns the number of purely unbounded joints.
int orderJoints(dxJoint* const* joint, unsigned nj, IslandWork& w) {
  w.active.clear();
  int count[3] = {0, 0, 0};
  for (unsigned k = 0; k < nj; ++k) {
    dxJoint::Info1 info;
    joint[k]->getInfo1(&info);
    joint[k]->tag = -1;  // inactive unless numbered below
    if (info.m > 0) {
      w.active.push_back({joint[k], info.m, info.nub, -1});
      ++count[jointClass(w.active.back())];
    }
  }
  int next[3] = {0, count[0], count[0] + count[1]};
  w.joints.resize(w.active.size());
  for (const JointRows& j : w.active) w.joints[next[jointClass(j)]++] = j;
  return count[0];
}

// Numbers the ordered joints (tag) and their first rows (offset); sizes the rows.
void numberRows(IslandWork& w) {
  int m = 0;
  for (std::size_t k = 0; k < w.joints.size(); ++k) {
    w.joints[k].joint->tag = static_cast<int>(k);
    w.joints[k].offset = m;
    m += w.joints[k].m;
  }
  RowSystem& rows = w.rows;
  rows.rows.resize(m);
  rows.b.resize(m);
  rows.lo.resize(m);
  rows.hi.resize(m);
  rows.cfm.resize(m);
  rows.findex.assign(m, -1);
}

// Stage 3a: getInfo2 of each joint into its rows; b holds ODE's rhs (c/h) until finishRhs.
void readJointRows(dxWorld* world, dReal h, IslandWork& w) {
  RowSystem& rows = w.rows;
  const dReal fps = dRecip(h);
  // getInfo2 writes each joint's Jacobian straight into its rows (J1 = jA, J2 = jB of the first
  // row, the next row kRowSkip dReals on): no staging arrays, no copy.
  static_assert(sizeof(ConstraintRow) % sizeof(dReal) == 0, "rows must be whole dReals apart");
  constexpr int kRowSkip = static_cast<int>(sizeof(ConstraintRow) / sizeof(dReal));
  for (const JointRows& jr : w.joints) {
    ConstraintRow* first = rows.rows.data() + jr.offset;
    // getInfo2 writes only the nonzero Jacobian entries.
    for (int k = 0; k < jr.m; ++k) {
      first[k].jA.setZero();
      first[k].jB.setZero();
    }
    dReal rhsCfm[6 * 2], loHi[6 * 2];
    int findex[6];
    for (int k = 0; k < jr.m; ++k) {
      rhsCfm[2 * k + dxJoint::GI2_RHS] = 0;
      rhsCfm[2 * k + dxJoint::GI2_CFM] = world->global_cfm;
      loHi[2 * k + dxJoint::GI2_LO] = -dInfinity;
      loHi[2 * k + dxJoint::GI2_HI] = dInfinity;
      findex[k] = -1;
    }
    jr.joint->getInfo2(fps, world->global_erp, kRowSkip, first->jA.data(), first->jB.data(), 2,
                       rhsCfm, loHi, findex);
    const dxBody* b0 = jr.joint->node[0].body;
    const dxBody* b1 = jr.joint->node[1].body;
    for (int k = 0; k < jr.m; ++k) {
      const int i = jr.offset + k;
      ConstraintRow& row = first[k];
      row.bodyA = b0->tag;
      row.bodyB = b1 ? b1->tag : -1;
      if (!b1) row.jB.setZero();
      rows.b[i] = rhsCfm[2 * k + dxJoint::GI2_RHS] * fps;  // ODE's rhs until finishRhs
      rows.cfm[i] = rhsCfm[2 * k + dxJoint::GI2_CFM] * fps;
      rows.lo[i] = loHi[2 * k + dxJoint::GI2_LO];
      rows.hi[i] = loHi[2 * k + dxJoint::GI2_HI];
      // findex is joint-local. An infinite friction coefficient needs no coupling (and the
      // core requires finite mu); ODE would only differ when the normal force is exactly 0.
      if (findex[k] != -1 && std::isfinite(rows.hi[i])) rows.findex[i] = findex[k] + jr.offset;
    }
  }
}

// Stage 3b: rhs = c/h - J (M^-1 f_ext + v/h), after every getInfo2 (joints may add to f_ext),
// stored as the canonical b = -rhs. The products are summed in dxStepIsland's order.
void finishRhs(dxBody* const* body, unsigned nb, dReal h, IslandWork& w) {
  RowSystem& rows = w.rows;
  const dReal fps = dRecip(h);
  std::vector<Vector6>& tmp = w.bodyTmp;
  tmp.resize(nb);
  for (unsigned i = 0; i < nb; ++i) {
    const dxBody* b = body[i];
    for (int k = 0; k < 3; ++k) tmp[i][k] = b->facc[k] * b->invMass + b->lvel[k] * fps;
    dMatrix3 invI;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) invI[r * 4 + c] = rows.bodies[i].invInertia(r, c);
    dVector3 a;
    dMultiply0_331(a, invI, b->tacc);
    for (int k = 0; k < 3; ++k) tmp[i][3 + k] = a[k] + b->avel[k] * fps;
  }
  auto dot6 = [](const Vector6& j, const Vector6& t) {
    double s = j[0] * t[0];
    for (int c = 1; c < kRowWidth; ++c) s += j[c] * t[c];
    return s;
  };
  for (int i = 0; i < rows.size(); ++i) {
    const ConstraintRow& row = rows.rows[i];
    double rhs = rows.b[i];
    rhs -= dot6(row.jA, tmp[row.bodyA]);
    if (row.bodyB >= 0) rhs -= dot6(row.jB, tmp[row.bodyB]);
    rows.b[i] = -rhs;  // canonical w = A x + b
  }
}

// Stages 2 and 3: the island's rows in the canonical form, joints ordered as dxStepIsland
// orders them. Returns the number of purely unbounded joints (what dxStepIsland passes to
// dxSolveLCP as nub).
int prepareRows(dxWorld* world, dxBody* const* body, unsigned nb, dxJoint* const* joint,
                unsigned nj, dReal h, IslandWork& w) {
  const int unboundedJoints = orderJoints(joint, nj, w);
  numberRows(w);
  readJointRows(world, h, w);
  finishRhs(body, nb, h, w);
  return unboundedJoints;
}

// Stage 6, as dxStepIsland_Stage4: feedback J^T lambda per joint and body, then
// v += h M^-1 (f_ext + J^T lambda), integrate, clear the accumulators.
void storeImpulses(dxBody* const* body, unsigned nb, const IslandWork& w, const Vector& x, dReal h,
                   std::vector<Vector6>& force) {
  force.assign(nb, Vector6::Zero());
  for (const JointRows& jr : w.joints) {
    for (int side = 0; side < 2; ++side) {
      const dxBody* b = jr.joint->node[side].body;
      if (!b) continue;
      Vector6 f = Vector6::Zero();
      for (int k = 0; k < jr.m; ++k) {
        const ConstraintRow& row = w.rows.rows[jr.offset + k];
        f += (side == 0 ? row.jA : row.jB) * x[jr.offset + k];
      }
      if (dJointFeedback* fb = jr.joint->feedback) {
        dReal* lin = side == 0 ? fb->f1 : fb->f2;
        dReal* ang = side == 0 ? fb->t1 : fb->t2;
        for (int k = 0; k < 3; ++k) {
          lin[k] = f[k];
          ang[k] = f[3 + k];
        }
      }
      force[b->tag] += f;
    }
  }
  for (unsigned i = 0; i < nb; ++i) {
    dxBody* b = body[i];
    const double hm = h * b->invMass;
    dVector3 angular;
    for (int k = 0; k < 3; ++k) {
      b->lvel[k] += (force[i][k] + b->facc[k]) * hm;
      angular[k] = (force[i][3 + k] + b->tacc[k]) * h;
    }
    const Eigen::Matrix3d& invI = w.rows.bodies[i].invInertia;
    for (int r = 0; r < 3; ++r)
      b->avel[r] += invI(r, 0) * angular[0] + invI(r, 1) * angular[1] + invI(r, 2) * angular[2];
    dxStepBody(b, h);
    dZeroVector3(b->facc);
    dZeroVector3(b->tacc);
  }
}

Accuracy islandAccuracy(const RowSystem& rows, const Vector& x) {
  return accuracy(x, rows.slack(x), rows.lo, rows.hi, rows.findex,
                  rows.size() ? rows.b.lpNorm<Eigen::Infinity>() : 0.0);
}

// ODE's own Dantzig solver on the island, in ODE's layout: A x = rhs + w with rhs = -b.
Result solveWithOdeLcp(IslandWork& w, int nub, dxWorldProcessMemArena* arena,
                       const Options& options, Vector& x) {
  const double t0 = nowSeconds();
  const unsigned m = static_cast<unsigned>(w.rows.size());
  const unsigned skip = dPAD(m);
  // The kept problem and scratch, as RowSolver assembles for our solvers: "ode-world" and
  // "auto" then time the same assembly code (see scene_loader.cpp).
  w.rows.assemble(false, w.odeProblem, w.odeScratch);
  const Problem& dense = w.odeProblem;
  // 64-byte aligned A, as dxStepIsland allocates it.
  w.odeA.assign(static_cast<std::size_t>(m) * skip + 8, 0.0);
  double* A = w.odeA.data();
  while (reinterpret_cast<std::uintptr_t>(A) % 64 != 0) ++A;
  for (unsigned r = 0; r < m; ++r)
    for (unsigned c = 0; c < m; ++c) A[r * skip + c] = dense.denseA()(r, c);
  w.odeBx.resize(2 * m);
  w.odeLh.resize(2 * m);
  w.odeFindex.resize(m);
  for (unsigned i = 0; i < m; ++i) {
    w.odeBx[2 * i + PBX_B] = -w.rows.b[i];
    w.odeBx[2 * i + PBX_X] = 0;
    w.odeLh[2 * i + PLH_LO] = w.rows.lo[i];
    w.odeLh[2 * i + PLH_HI] = w.rows.hi[i];
    w.odeFindex[i] = w.rows.findex[i];
  }
  void* state = arena->SaveState();
  dxSolveLCP(arena, m, A, w.odeBx.data(), nullptr, static_cast<unsigned>(nub), w.odeLh.data(),
             w.odeFindex.data());
  arena->RestoreState(state);
  x.resize(m);
  for (unsigned i = 0; i < m; ++i) x[i] = w.odeBx[2 * i + PBX_X];
  Result r;
  r.status = Status::Converged;  // dxSolveLCP reports nothing; the residual decides
  r.message = "ODE dxSolveLCP";
  // w = A x + b from the assembled A (dxSolveLCP destroyed only ODE's copy), as Solver's check
  // does for ours.
  w.odeSlack.noalias() = dense.denseA() * x;
  w.odeSlack += dense.b;
  applyAccuracy(r, accuracy(dense, x, w.odeSlack), options.tolerance);
  r.seconds = nowSeconds() - t0;
  return r;
}

}  // namespace

Method makeMethod(const std::string& name, RowSolverSettings settings) {
  Method m;
  m.name = name;
  if (settings.friction == FrictionModel::Cone && name.rfind("ode-", 0) == 0)
    throw std::invalid_argument("mlcp::ode::Stepper: friction 'cone' needs a core solver; '" +
                                name + "' is ODE's own (box friction)");
  if (name == "ode-step") {
    m.kind = Method::Kind::ForwardStep;
  } else if (name == "ode-quickstep") {
    m.kind = Method::Kind::ForwardQuickStep;
  } else if (name == "ode-lcp") {
    m.kind = Method::Kind::OdeLcp;
  } else {
    if (!RowSolver::known(name))
      throw std::invalid_argument("mlcp::ode::Stepper: unknown solver '" + name +
                                  "' (known: " + Stepper::knownSolvers() + ")");
    settings.solver = name;
    settings.timeAssembly = false;  // IslandStats has no assembly time: one clock read less
    m.kind = Method::Kind::Core;
    m.solver = std::make_unique<RowSolver>(settings);
  }
  return m;
}

// --- warm start ----------------------------------------------------------------------------

WarmStartCache::Key WarmStartCache::keyOf(dxJoint* joint) {
  Key k;
  k.contact = joint->type() == dJointTypeContact;
  if (k.contact) {
    k.a = reinterpret_cast<std::uintptr_t>(joint->node[0].body);
    k.b = reinterpret_cast<std::uintptr_t>(joint->node[1].body);
  } else {
    k.a = reinterpret_cast<std::uintptr_t>(joint);
  }
  return k;
}

namespace {

std::size_t slotOf(std::uintptr_t a, std::uintptr_t b, std::size_t mask) {
  std::uint64_t h = (a >> 4) * 0x9E3779B97F4A7C15ull ^ (b >> 4) * 0xC2B2AE3D27D4EB4Full;
  return static_cast<std::size_t>(h ^ (h >> 29)) & mask;
}

}  // namespace

int WarmStartCache::find(const Key& key) const {
  if (table_.empty()) return -1;
  const std::size_t mask = table_.size() - 1;
  for (std::size_t s = slotOf(key.a, key.b, mask);; s = (s + 1) & mask) {
    const int i = table_[s];
    if (i < 0 || entries_[i].key == key) return i;
  }
}

bool WarmStartCache::lookup(dxJoint* joint, int m, double* lambda, double matchDistance) {
  const Key key = keyOf(joint);
  int i = find(key);
  if (i < 0) return false;
  if (key.contact) {
    const dReal* pos = static_cast<dxJointContact*>(joint)->contact.geom.pos;
    double d2 = 0;
    i = nearestContact(i, pos, m, d2);
    if (i < 0 || d2 > matchDistance * matchDistance) return false;
    std::copy(entries_[i].lambda.begin(), entries_[i].lambda.begin() + m, lambda);
    return true;
  }
  const Entry& e = entries_[i];
  if (e.type != joint->type() || e.m != m || e.body0 != joint->node[0].body ||
      e.body1 != joint->node[1].body)
    return false;
  std::copy(e.lambda.begin(), e.lambda.begin() + m, lambda);
  return true;
}

int WarmStartCache::nearestContact(int first, const dReal* pos, int m, double& d2) const {
  int best = -1;
  for (int i = first; i >= 0; i = entries_[i].next) {
    const Entry& e = entries_[i];
    if (e.m != m) continue;
    const double d = (pos[0] - e.pos[0]) * (pos[0] - e.pos[0]) +
                     (pos[1] - e.pos[1]) * (pos[1] - e.pos[1]) +
                     (pos[2] - e.pos[2]) * (pos[2] - e.pos[2]);
    if (best < 0 || d < d2) best = i, d2 = d;
  }
  return best;
}

void WarmStartCache::store(dxJoint* joint, int m, const double* lambda) {
  Entry& e = next_.emplace_back();
  e.key = keyOf(joint);
  e.type = joint->type();
  e.m = m;
  e.body0 = joint->node[0].body;
  e.body1 = joint->node[1].body;
  if (e.key.contact) {
    const dReal* pos = static_cast<dxJointContact*>(joint)->contact.geom.pos;
    std::copy(pos, pos + 3, e.pos.begin());
  }
  std::copy(lambda, lambda + m, e.lambda.begin());
}

void WarmStartCache::endStep() {
  entries_.swap(next_);
  next_.clear();
  std::size_t size = 16;
  while (size < 2 * entries_.size()) size *= 2;
  table_.assign(size, -1);
  const std::size_t mask = size - 1;
  for (int i = 0; i < static_cast<int>(entries_.size()); ++i) {
    Entry& e = entries_[i];
    for (std::size_t s = slotOf(e.key.a, e.key.b, mask);; s = (s + 1) & mask) {
      const int j = table_[s];
      if (j < 0) {
        table_[s] = e.last = i;
        break;
      }
      if (entries_[j].key == e.key) {  // a joint stored twice keeps its first entry
        if (e.key.contact) {
          entries_[entries_[j].last].next = i;
          entries_[j].last = i;
        }
        break;
      }
    }
  }
}

void WarmStartCache::clear() {
  entries_.clear();
  next_.clear();
  table_.clear();
}

}  // namespace mlcp::ode

// --- the island stepper --------------------------------------------------------------------

namespace mlcp::ode {

namespace {

// Stage 5 with ODE's own solver or a core one (RowSolver: choice, verification, fallback).
// Nothing usable leaves the start (the caller's warm start), as RowSolver does.
IslandSolve solveWith(Method& method, IslandWork& w, int nub, dxWorldProcessMemArena* arena,
                      const Settings& so, const Options& options, std::uint64_t key, Vector& x) {
  if (method.kind == Method::Kind::Core) {
    method.solver->options() = options;
    return method.solver->solve(w.rows, w.x0, x, key);
  }
  IslandSolve out;
  out.problemClass = classify(w.rows);
  out.choice = out.requested = method.name;
  if (method.kind == Method::Kind::OdeLcp) {
    out.result = solveWithOdeLcp(w, nub, arena, options, x);
    out.accepted = acceptable(out.result, so.acceptResidual);
    if (!x.allFinite()) {
      x = w.x0;
      applyAccuracy(out.result, islandAccuracy(w.rows, x), options.tolerance);
      out.result.message += "; start kept";
    }
    return out;
  }
  out.result.status = Status::Unsupported;
  out.result.message = method.name + " forwards whole islands and cannot solve a problem";
  out.accepted = false;
  return out;
}

}  // namespace

}  // namespace mlcp::ode

using mlcp::ode::IslandWork;
using mlcp::ode::JointRows;
using mlcp::ode::Method;

void mlcp::ode::Stepper::Impl::runIsland(const dxStepperProcessingCallContext* ctx) {
  std::lock_guard<std::mutex> lock(mutex);
  const double t0 = nowSeconds();
  dxBody* const* body = ctx->m_islandBodiesStart;
  const unsigned nb = ctx->m_islandBodiesCount;
  const dReal h = ctx->m_stepSize;

  const int island = static_cast<int>(islandsUsed);
  IslandStats& st = nextIslandStats();
  st.bodies = static_cast<int>(nb);
  if (primary.forwards()) {
    forwardIsland(ctx, st);
    st.islandSeconds = nowSeconds() - t0;
    return;
  }

  IslandWork& w = work;
  prepareBodies(ctx->m_world, body, nb, h, w.rows);
  const int nub =
      prepareRows(ctx->m_world, body, nb, ctx->m_islandJointsStart, ctx->m_islandJointsCount, h, w);
  const int m = w.rows.size();
  st.joints = static_cast<int>(w.joints.size());
  st.rows = m;
  for (int i = 0; i < m; ++i) st.unbounded += w.rows.lo[i] == -kInf && w.rows.hi[i] == kInf;

  if (m > 0) {
    st.warmStarted = warmStartIsland(w);
    solveIsland(ctx, nub, st);
    for (const JointRows& jr : w.joints) this->warm.store(jr.joint, jr.m, w.x.data() + jr.offset);
  } else {
    w.x.resize(0);
    st.residual = 0;
    st.message = "no constraint rows";
    st.choice = "none";
  }

  // Stage 6: store impulses and integrate.
  storeImpulses(body, nb, w, w.x, h, w.bodyTmp);
  st.islandSeconds = nowSeconds() - t0;
  if (options.keepProblems && m > 0) keepProblem(w, island);
}

mlcp::ode::IslandStats& mlcp::ode::Stepper::Impl::nextIslandStats() {
  if (islandsUsed == stats.islands.size()) stats.islands.emplace_back();
  IslandStats& st = stats.islands[islandsUsed++];
  st = IslandStats{};  // the strings keep their buffers (a short string's move copies)
  return st;
}

void mlcp::ode::Stepper::Impl::forwardIsland(const dxStepperProcessingCallContext* ctx,
                                             IslandStats& st) {
  dxJoint* const* joint = ctx->m_islandJointsStart;
  for (unsigned k = 0; k < ctx->m_islandJointsCount; ++k) {
    dxJoint::Info1 info;
    joint[k]->getInfo1(&info);
    st.joints += info.m > 0;
    st.rows += info.m;
  }
  if (primary.kind == Method::Kind::ForwardStep)
    dxStepIsland(ctx);
  else
    dxQuickStepIsland(ctx);
  st.message = primary.name;
}

bool mlcp::ode::Stepper::Impl::warmStartIsland(IslandWork& w) {
  // Stage 4: warm start (zeros where nothing matches).
  w.x0.setZero(w.rows.size());
  bool warmed = false;
  if (options.warmStart)
    for (const JointRows& jr : w.joints)
      warmed |= warm.lookup(jr.joint, jr.m, w.x0.data() + jr.offset, options.contactMatchDistance);
  return warmed;
}

void mlcp::ode::Stepper::Impl::solveIsland(const dxStepperProcessingCallContext* ctx, int nub,
                                           IslandStats& st) {
  // Stage 5: solve, verify, fall back (RowSolver), keyed by the island's first body.
  IslandWork& w = work;
  const std::uint64_t key = reinterpret_cast<std::uintptr_t>(ctx->m_islandBodiesStart[0]);
  // The solve's own clock (RowSolver::solve's span, or solveWithOdeLcp's): no second pair of
  // clock reads around it.
  IslandSolve solved =
      solveWith(primary, w, nub, ctx->m_stepperArena, options, stepOptions, key, w.x);
  st.solveSeconds = solved.result.seconds;
  st.status = solved.result.status;
  st.iterations = solved.result.iterations;
  st.residual = solved.result.residual;
  st.message = std::move(solved.result.message);
  st.choice = std::move(solved.choice);
  st.fellBack = solved.fellBack;
  st.accepted = solved.accepted;
  st.screened = solved.screened;
  st.friction = solved.friction;
  if (hasReference) compareWithReference(ctx, nub, key, st);
}

void mlcp::ode::Stepper::Impl::compareWithReference(const dxStepperProcessingCallContext* ctx,
                                                    int nub, std::uint64_t key, IslandStats& st) {
  IslandWork& w = work;
  const double tr = nowSeconds();
  const IslandSolve rr =
      solveWith(reference, w, nub, ctx->m_stepperArena, options, stepOptions, key, w.xAlt);
  st.referenceSeconds = nowSeconds() - tr;
  if (std::isfinite(rr.result.residual) && w.xAlt.size() == w.rows.size()) {
    st.referenceResidual = rr.result.residual;
    st.referenceDifference =
        (w.xAlt - w.x).lpNorm<Eigen::Infinity>() / (1 + w.x.lpNorm<Eigen::Infinity>());
  } else {
    st.referenceResidual = st.referenceDifference = kInf;
  }
}
