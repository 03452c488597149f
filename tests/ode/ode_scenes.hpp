// Scenes built in code for the ODE adapter's tests and benchmark (until scene files exist).
// Each scene is an ordinary ODE program's world: bodies, joints, geoms in a simple space,
// contacts from dCollide into a joint group emptied every step, so that a stepper is swapped
// exactly as a user would swap dWorldStep.
#pragma once

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "mlcp/ode/stepper.hpp"

namespace mlcp::ode::test {

// Our pgs as QuickStep runs: a fixed number of sweeps with SOR factor 1.3 (QuickStep's
// default), no convergence test, no fallback.
inline Settings fixedSweepPgs(int sweeps, bool keepProblems = false) {
  Settings o;
  o.options.maxIterations = sweeps;
  o.options.checkEvery = sweeps;
  o.options.tolerance = 0;
  o.options.relaxation = 1.3;
  o.engineIterations = false;
  o.fallback = "";
  o.keepProblems = keepProblems;
  o.timeBudget = 0;  // fixed work per step, comparable bit for bit: no wall-clock cut
  return o;
}

// max_i |a_i - b_i| (Scene::state() of two worlds); +inf when the sizes differ.
inline double maxAbsDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = a.size() == b.size() ? 0.0 : INFINITY;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
    d = std::max(d, std::fabs(a[i] - b[i]));
  return d;
}

inline void ensureOdeInitialized() {
  static const bool done = [] {
    dInitODE2(0);
    return true;
  }();
  (void)done;
}

// A step function: dWorldStep, dWorldQuickStep, or a lambda around mlcp::ode::Stepper.
using StepFn = std::function<void(dWorldID, dReal)>;

struct Surface {
  int mode = dContactApprox1;  // Coulomb friction proportional to the normal force (findex)
  dReal mu = 0.5;
  dReal softErp = 0, softCfm = 0;  // used when mode has dContactSoftERP / dContactSoftCFM
  dReal bounce = 0, bounceVel = 0;
  int maxContacts = 4;         // per geom pair
  dVector3 fdir1 = {1, 0, 0};  // first friction direction, with mode dContactFDir1
};

class Scene {
 public:
  Scene() {
    ensureOdeInitialized();
    world = dWorldCreate();
    space = dSimpleSpaceCreate(nullptr);
    contacts = dJointGroupCreate(0);
    dWorldSetGravity(world, 0, 0, -9.81);
  }
  ~Scene() {
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  dBodyID addBox(dReal x, dReal y, dReal z, dReal lx, dReal ly, dReal lz, dReal density = 1.0) {
    dBodyID b = dBodyCreate(world);
    dMass m;
    dMassSetBox(&m, density, lx, ly, lz);
    dBodySetMass(b, &m);
    dBodySetPosition(b, x, y, z);
    dGeomID g = dCreateBox(space, lx, ly, lz);
    dGeomSetBody(g, b);
    bodies.push_back(b);
    return b;
  }
  dBodyID addSphereBody(dReal x, dReal y, dReal z, dReal radius, dReal mass, bool geom = false) {
    dBodyID b = dBodyCreate(world);
    dMass m;
    dMassSetSphereTotal(&m, mass, radius);
    dBodySetMass(b, &m);
    dBodySetPosition(b, x, y, z);
    if (geom) dGeomSetBody(dCreateSphere(space, radius), b);
    bodies.push_back(b);
    return b;
  }
  // The plane n . p = d (n normalized by ODE).
  dGeomID addPlane(dReal nx, dReal ny, dReal nz, dReal d) {
    return dCreatePlane(space, nx, ny, nz, d);
  }
  dJointID track(dJointID j, bool feedback = true) {
    if (feedback) {
      feedbacks.push_back(std::make_unique<dJointFeedback>());
      dJointSetFeedback(j, feedbacks.back().get());
    }
    joints.push_back(j);
    return j;
  }

  // Collide, step, drop the contacts: one frame of an ODE program.
  void step(const StepFn& stepFn, dReal h) {
    ++frame_;
    lastContacts_ = 0;
    contactRecords_.clear();
    dSpaceCollide(space, this, &Scene::nearCallback);
    stepFn(world, h);
    dJointGroupEmpty(contacts);
  }
  int lastContacts() const { return lastContacts_; }

  // This step's contact joints in creation order (dCollide's, deterministic), kept while
  // recordContacts is set, each with a dJointFeedback when contactFeedback is set too: the
  // benchmark matches contacts across identically built piles and reads their forces.
  struct ContactRecord {
    dJointID joint;
    dContactGeom geom;
    int body0, body1;          // indices in `bodies` of the joint's two bodies, -1 for none
    dJointFeedback* feedback;  // null unless contactFeedback
  };
  bool recordContacts = false, contactFeedback = false;
  // Each frame, a pair's contacts are created in dCollide's order rotated by the frame number:
  // the same points, in another order every step (as colliders that cull or sort points give).
  bool rotateContacts = false;
  const std::vector<ContactRecord>& contactRecords() const { return contactRecords_; }
  int bodyIndex(dBodyID b) const {
    const auto it = std::find(bodies.begin(), bodies.end(), b);
    return b && it != bodies.end() ? static_cast<int>(it - bodies.begin()) : -1;
  }

  // Position, quaternion, linear and angular velocity of every body, in body order.
  std::vector<double> state() const {
    std::vector<double> s;
    for (dBodyID b : bodies) {
      const dReal* p = dBodyGetPosition(b);
      const dReal* q = dBodyGetQuaternion(b);
      const dReal* v = dBodyGetLinearVel(b);
      const dReal* w = dBodyGetAngularVel(b);
      s.insert(s.end(),
               {p[0], p[1], p[2], q[0], q[1], q[2], q[3], v[0], v[1], v[2], w[0], w[1], w[2]});
    }
    return s;
  }
  // Every feedback value (f1 t1 f2 t2 of each tracked joint with feedback).
  std::vector<double> feedback() const {
    std::vector<double> s;
    for (const auto& fb : feedbacks)
      for (const dReal* v : {fb->f1, fb->t1, fb->f2, fb->t2}) s.insert(s.end(), v, v + 3);
    return s;
  }

  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  Surface surface;
  std::vector<dBodyID> bodies;
  std::vector<dJointID> joints;
  std::vector<std::unique_ptr<dJointFeedback>> feedbacks;

 private:
  static void nearCallback(void* data, dGeomID a, dGeomID b) {
    Scene* s = static_cast<Scene*>(data);
    dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
    if (ba && bb && dAreConnectedExcluding(ba, bb, dJointTypeContact)) return;
    std::vector<dContact> c(s->surface.maxContacts);
    const int n = dCollide(a, b, s->surface.maxContacts, &c[0].geom, sizeof(dContact));
    if (s->rotateContacts && n > 1)
      std::rotate(c.begin(), c.begin() + s->frame_ % n, c.begin() + n);
    for (int i = 0; i < n; ++i) {
      c[i].surface.mode = s->surface.mode;
      c[i].surface.mu = s->surface.mu;
      c[i].surface.soft_erp = s->surface.softErp;
      c[i].surface.soft_cfm = s->surface.softCfm;
      c[i].surface.bounce = s->surface.bounce;
      c[i].surface.bounce_vel = s->surface.bounceVel;
      for (int k = 0; k < 3; ++k) c[i].fdir1[k] = s->surface.fdir1[k];
      dJointID j = dJointCreateContact(s->world, s->contacts, &c[i]);
      dJointAttach(j, ba, bb);
      if (s->recordContacts) s->record(j, c[i].geom);
    }
    s->lastContacts_ += n;
  }
  void record(dJointID j, const dContactGeom& geom) {
    dJointFeedback* fb = nullptr;
    if (contactFeedback) {
      // One feedback per contact slot, reused every step.
      if (contactRecords_.size() == contactFeedbacks_.size())
        contactFeedbacks_.push_back(std::make_unique<dJointFeedback>());
      fb = contactFeedbacks_[contactRecords_.size()].get();
      dJointSetFeedback(j, fb);
    }
    contactRecords_.push_back(
        {j, geom, bodyIndex(dJointGetBody(j, 0)), bodyIndex(dJointGetBody(j, 1)), fb});
  }
  int lastContacts_ = 0;
  int frame_ = 0;  // steps taken, for rotateContacts
  std::vector<ContactRecord> contactRecords_;
  std::vector<std::unique_ptr<dJointFeedback>> contactFeedbacks_;
};

// --- the scenes ---------------------------------------------------------------------------------

// A chain of n capsule-like boxes hanging from the world by hinges about y, started at a small
// angle: nearly linear (not chaotic) motion in the x-z plane.
inline std::unique_ptr<Scene> pendulumChain(int n = 3, dReal angle = 0.2) {
  auto s = std::make_unique<Scene>();
  const dReal len = 0.5;
  dBodyID prev = nullptr;
  for (int i = 0; i < n; ++i) {
    const dReal r0 = i * len, r1 = (i + 0.5) * len;
    dBodyID b = dBodyCreate(s->world);
    dMass m;
    dMassSetBoxTotal(&m, 1.0, 0.05, 0.05, len);
    dBodySetMass(b, &m);
    dBodySetPosition(b, r1 * std::sin(angle), 0, 2 - r1 * std::cos(angle));
    dMatrix3 R;
    dRFromAxisAndAngle(R, 0, 1, 0, angle);
    dBodySetRotation(b, R);
    s->bodies.push_back(b);
    dJointID j = dJointCreateHinge(s->world, nullptr);
    dJointAttach(j, b, prev);
    dJointSetHingeAnchor(j, r0 * std::sin(angle), 0, 2 - r0 * std::cos(angle));
    dJointSetHingeAxis(j, 0, 1, 0);
    s->track(j);
    prev = b;
  }
  return s;
}

// One body on a hinge with stops at +-0.3 rad and a motor driving it into the upper stop.
inline std::unique_ptr<Scene> hingeLimitMotor() {
  auto s = std::make_unique<Scene>();
  dBodyID b = s->addSphereBody(0.5, 0, 1, 0.1, 2.0);
  dJointID j = dJointCreateHinge(s->world, nullptr);
  dJointAttach(j, b, nullptr);
  dJointSetHingeAnchor(j, 0, 0, 1);
  dJointSetHingeAxis(j, 0, 1, 0);
  dJointSetHingeParam(j, dParamLoStop, -0.3);
  dJointSetHingeParam(j, dParamHiStop, 0.3);
  dJointSetHingeParam(j, dParamVel, 1.5);
  dJointSetHingeParam(j, dParamFMax, 3.0);
  dJointSetHingeParam(j, dParamBounce, 0.2);
  s->track(j);
  return s;
}

// A box on a slider along a tilted axis with a motor against gravity and both stops.
inline std::unique_ptr<Scene> sliderScene() {
  auto s = std::make_unique<Scene>();
  dBodyID b = s->addSphereBody(0, 0, 1, 0.1, 1.0);
  dJointID j = dJointCreateSlider(s->world, nullptr);
  dJointAttach(j, b, nullptr);
  dJointSetSliderAxis(j, 1, 0, 1);
  dJointSetSliderParam(j, dParamLoStop, -0.4);
  dJointSetSliderParam(j, dParamHiStop, 0.2);
  dJointSetSliderParam(j, dParamVel, 0.5);
  dJointSetSliderParam(j, dParamFMax, 5.0);
  s->track(j);
  return s;
}

// A box on the ground plane z = 0, at rest or sliding along x with speed vx.
inline std::unique_ptr<Scene> boxOnPlane(dReal vx = 0, dReal mu = 0.5) {
  auto s = std::make_unique<Scene>();
  s->surface.mu = mu;
  s->addPlane(0, 0, 1, 0);
  dBodyID b = s->addBox(0, 0, 0.25, 0.5, 0.5, 0.5);
  dBodySetLinearVel(b, vx, 0, 0);
  return s;
}

// n boxes stacked on the ground plane, dropped from 1 mm gaps (an exactly touching start with
// 11 of 12 contacts makes stock dSolveLCP stop with "s <= 0" on the first step).
inline std::unique_ptr<Scene> boxStack(int n = 3) {
  auto s = std::make_unique<Scene>();
  s->addPlane(0, 0, 1, 0);
  const dReal gap = 0.001;
  for (int i = 0; i < n; ++i) s->addBox(0, 0, 0.25 + (0.5 + gap) * i + gap, 0.5, 0.5, 0.5);
  return s;
}

// A 2D pyramid of boxes (base boxes on the ground, each row resting on the one below): about
// 12 constraint rows per box once settled (4 contacts of 3 rows each).
inline std::unique_ptr<Scene> boxPyramid(int base, dReal mu = 0.6) {
  auto s = std::make_unique<Scene>();
  s->surface.mu = mu;
  s->addPlane(0, 0, 1, 0);
  const dReal size = 0.5, gap = 0.02;
  for (int row = 0; row < base; ++row)
    for (int k = 0; k < base - row; ++k)
      s->addBox((k + 0.5 * row) * (size + gap), 0, 0.5 * size + row * size, size, size, size);
  return s;
}

// Sets every body of `to` to the state of the same body of `from` (identically built scenes):
// the benchmarks step several methods from one reference state.
inline void copyState(const Scene& from, Scene& to) {
  for (std::size_t i = 0; i < from.bodies.size(); ++i) {
    dBodyID a = from.bodies[i], b = to.bodies[i];
    const dReal* p = dBodyGetPosition(a);
    const dReal* v = dBodyGetLinearVel(a);
    const dReal* w = dBodyGetAngularVel(a);
    dBodySetPosition(b, p[0], p[1], p[2]);
    dBodySetQuaternion(b, dBodyGetQuaternion(a));
    dBodySetLinearVel(b, v[0], v[1], v[2]);
    dBodySetAngularVel(b, w[0], w[1], w[2]);
  }
}

// The largest difference of any body's linear or angular velocity component (m/s, rad/s).
inline double velocityDifference(const Scene& a, const Scene& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.bodies.size(); ++i)
    for (auto get : {dBodyGetLinearVel, dBodyGetAngularVel}) {
      const dReal *u = get(a.bodies[i]), *v = get(b.bodies[i]);
      for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(double(u[k] - v[k])));
    }
  return d;
}

}  // namespace mlcp::ode::test
