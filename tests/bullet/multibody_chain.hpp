// tests/bullet/multibody_chain.hpp: a multibody world built in code for the multibody tests: a
// 4-link revolute arm on a fixed base (a velocity motor on its first joint, +-0.25 rad limits on
// the others) beside three boxes on the ground.
#pragma once

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btDefaultCollisionConfiguration.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace mlcp_test {

constexpr int kLinks = 4;
constexpr double kLimit = 0.25;     // rad, joints 1..3
constexpr double kDt = 1.0 / 60.0;  // s

// The chain world; everything it makes it owns.
class Chain {
 public:
  // Makes the world (a btMultiBodyDynamicsWorld, or a world derived from it).
  using WorldMaker = btMultiBodyDynamicsWorld* (*)(btDispatcher*, btBroadphaseInterface*,
                                                   btMultiBodyConstraintSolver*,
                                                   btCollisionConfiguration*);
  static btMultiBodyDynamicsWorld* plainWorld(btDispatcher* d, btBroadphaseInterface* b,
                                              btMultiBodyConstraintSolver* s,
                                              btCollisionConfiguration* c) {
    return new btMultiBodyDynamicsWorld(d, b, s, c);
  }

  // motorSpeed: the first joint's target velocity (rad/s; 0 holds it against its max impulse).
  // solver: the world's multibody solver (null: Bullet's btMultiBodyConstraintSolver).
  explicit Chain(bool splitImpulse = true, double motorSpeed = -1,
                 btMultiBodyConstraintSolver* solver = nullptr, WorldMaker make = plainWorld)
      : motorSpeed_(motorSpeed) {
    world_.reset(make(&dispatcher_, &broadphase_, solver ? solver : &stock_, &config_));
    world_->setGravity(btVector3(0, -9.81, 0));
    world_->getSolverInfo().m_splitImpulse = splitImpulse;
    addBox(btVector3(5, 0.5, 5), btVector3(0, -0.5, 0), 0);  // the ground
    for (int k = 0; k < 3; ++k)
      addBox(btVector3(0.1, 0.1, 0.1), btVector3(0.5 + 0.3 * k, 0.1, 0), 1);
    addArm();
  }
  ~Chain() {
    for (auto& c : constraints_) world_->removeMultiBodyConstraint(c.get());
    for (auto& c : colliders_) world_->removeCollisionObject(c.get());
    world_->removeMultiBody(arm_.get());
    for (auto& b : bodies_) world_->removeRigidBody(b.get());
  }
  btMultiBodyDynamicsWorld& world() { return *world_; }
  btMultiBody& arm() { return *arm_; }

  // Steps; returns the fastest linear speed seen (m/s: the boxes', and the links' centres' from
  // their motion over the step), NaN if a position is not finite.
  double step(int frames) {
    double fastest = 0;
    for (int f = 0; f < frames; ++f) {
      std::vector<btVector3> before;
      for (int i = 0; i < kLinks; ++i)
        before.push_back(arm_->getLink(i).m_collider->getWorldTransform().getOrigin());
      world_->stepSimulation(kDt, 0);
      for (auto& b : bodies_) {
        if (!std::isfinite(b->getWorldTransform().getOrigin().y())) return NAN;
        fastest = std::max(fastest, double(b->getLinearVelocity().length()));
      }
      for (int i = 0; i < kLinks; ++i) {
        const btVector3 now = arm_->getLink(i).m_collider->getWorldTransform().getOrigin();
        if (!std::isfinite(arm_->getJointPos(i)) || !std::isfinite(now.y())) return NAN;
        fastest = std::max(fastest, double((now - before[i]).length()) / kDt);
      }
    }
    return fastest;
  }
  // The largest limit violation of joints 1..3 (rad), and their largest speed (rad/s).
  double violation() const {
    double v = 0;
    for (int i = 1; i < kLinks; ++i)
      v = std::max(v, std::abs(double(arm_->getJointPos(i))) - kLimit);
    return v;
  }
  double limitedSpeed() const {
    double v = 0;
    for (int i = 1; i < kLinks; ++i) v = std::max(v, std::abs(double(arm_->getJointVel(i))));
    return v;
  }

 private:
  void addBox(const btVector3& half, const btVector3& at, double mass) {
    shapes_.push_back(std::make_unique<btBoxShape>(half));
    btVector3 inertia(0, 0, 0);
    if (mass > 0) shapes_.back()->calculateLocalInertia(mass, inertia);
    btRigidBody::btRigidBodyConstructionInfo ci(mass, nullptr, shapes_.back().get(), inertia);
    ci.m_startWorldTransform.setOrigin(at);
    bodies_.push_back(std::make_unique<btRigidBody>(ci));
    bodies_.back()->setActivationState(DISABLE_DEACTIVATION);
    world_->addRigidBody(bodies_.back().get());
  }
  void addArm() {
    const btVector3 half(0.05, 0.15, 0.05);
    btVector3 inertia;
    btBoxShape(half).calculateLocalInertia(1, inertia);
    arm_ = std::make_unique<btMultiBody>(kLinks, 1, btVector3(1, 1, 1), true, false);
    arm_->setBasePos(btVector3(0, 0.95, 0));  // hanging straight, its tip would be 0.25 m deep
    // Each pivot half a link below its parent's centre (the base's: at it); each centre half a
    // link below its pivot.
    const btVector3 halfDown(0, -half[1], 0);
    for (int i = 0; i < kLinks; ++i)
      arm_->setupRevolute(i, 1, inertia, i - 1, btQuaternion(0, 0, 0, 1), btVector3(0, 0, 1),
                          i == 0 ? btVector3(0, 0, 0) : halfDown, halfDown, true);
    arm_->finalizeMultiDof();
    arm_->setJointPos(0, 1.2);  // swung out: it falls, sweeps the boxes and bends at its limits
    world_->addMultiBody(arm_.get());
    btAlignedObjectArray<btQuaternion> rot;
    btAlignedObjectArray<btVector3> origin;
    for (int i = 0; i < kLinks; ++i) {
      shapes_.push_back(std::make_unique<btBoxShape>(half));
      colliders_.push_back(std::make_unique<btMultiBodyLinkCollider>(arm_.get(), i));
      colliders_.back()->setCollisionShape(shapes_.back().get());
      world_->addCollisionObject(colliders_.back().get());  // every group: the ground too
      arm_->getLink(i).m_collider = colliders_.back().get();
    }
    arm_->updateCollisionObjectWorldTransforms(rot, origin);
    constraints_.push_back(
        std::make_unique<btMultiBodyJointMotor>(arm_.get(), 0, motorSpeed_, 5.0));
    for (int i = 1; i < kLinks; ++i)
      constraints_.push_back(
          std::make_unique<btMultiBodyJointLimitConstraint>(arm_.get(), i, -kLimit, kLimit));
    for (auto& c : constraints_) world_->addMultiBodyConstraint(c.get());
  }

  double motorSpeed_;
  btDefaultCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_{&config_};
  btDbvtBroadphase broadphase_;
  btMultiBodyConstraintSolver stock_;
  std::unique_ptr<btMultiBodyDynamicsWorld> world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::unique_ptr<btMultiBody> arm_;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> constraints_;
};

}  // namespace mlcp_test
