// A scene's articulations as btMultiBodies (reduced coordinates), and every body's state
// (see scene_loader.hpp).
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>

#include <vector>

#include "mlcp/bullet/scene_loader.hpp"
#include "scene_bullet.hpp"

namespace mlcp::bullet {

namespace {

// A link's frames for btMultiBody::setup*: everything in the parent's or the link's own frame,
// from the world poses at creation (where every joint coordinate is 0).
struct LinkFrames {
  btQuaternion parentToThis;  // rotates parent-frame vectors into the link frame
  btVector3 axis;             // the joint axis, link frame
  btVector3 parentToPivot;    // parent's centre of mass to the anchor, parent frame
  btVector3 pivotToThis;      // anchor to the link's centre of mass, link frame
};

LinkFrames framesOf(const btTransform& parent, const btTransform& link, const scene::Joint& j) {
  const btQuaternion toLink = link.getRotation().inverse();
  LinkFrames f;
  f.parentToThis = toLink * parent.getRotation();
  f.axis = quatRotate(toLink, bt(j.axis));
  f.parentToPivot = quatRotate(parent.getRotation().inverse(), bt(j.anchor) - parent.getOrigin());
  f.pivotToThis = quatRotate(toLink, link.getOrigin() - bt(j.anchor));
  return f;
}

void setupLink(btMultiBody& mb, int k, int parent, const scene::Body& b, const scene::Joint& j,
               const LinkFrames& f) {
  const btVector3 inertia = bt(b.inertia);
  // Parent and child never collide, as in the maximal loaders (collide_connected false).
  switch (j.type) {
    case scene::JointType::Hinge:
      mb.setupRevolute(k, b.mass, inertia, parent, f.parentToThis, f.axis, f.parentToPivot,
                       f.pivotToThis, true);
      break;
    case scene::JointType::Slider:
      mb.setupPrismatic(k, b.mass, inertia, parent, f.parentToThis, f.axis, f.parentToPivot,
                        f.pivotToThis, true);
      break;
    case scene::JointType::Ball:
      mb.setupSpherical(k, b.mass, inertia, parent, f.parentToThis, f.parentToPivot, f.pivotToThis,
                        true);
      break;
    default:  // the parser makes only these four types in an articulation
      mb.setupFixed(k, b.mass, inertia, parent, f.parentToThis, f.parentToPivot, f.pivotToThis,
                    true);
      break;
  }
}

}  // namespace

btMultiBodyLinkCollider* BulletScene::addCollider(const scene::Scene& s, const scene::Body& b,
                                                  btMultiBody* mb, int link) {
  shapes_.push_back(makeShape(b));
  colliders_.push_back(std::make_unique<btMultiBodyLinkCollider>(mb, link));
  btMultiBodyLinkCollider* c = colliders_.back().get();
  c->setCollisionShape(shapes_.back().get());
  c->setWorldTransform(poseOf(b));
  setMaterial(*c, s.materials[b.material]);
  const bool isStatic = b.isStatic();
  const int group = isStatic ? btBroadphaseProxy::StaticFilter : btBroadphaseProxy::DefaultFilter;
  const int mask = isStatic ? btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter
                            : btBroadphaseProxy::AllFilter;
  world_->addCollisionObject(c, group, mask);
  if (!isStatic && !s.settings.sleeping) c->setActivationState(DISABLE_DEACTIVATION);
  return c;
}

void BulletScene::addMultiBody(const scene::Scene& s, const scene::Articulation& a) {
  const scene::Body& base = s.bodies[a.base];
  const int n = static_cast<int>(a.links.size());
  multiBodies_.push_back(
      std::make_unique<btMultiBody>(n, base.mass, bt(base.inertia), a.fixedBase, false));
  btMultiBody& mb = *multiBodies_.back();
  multiBodyPointers_.push_back(&mb);
  mb.setBaseWorldTransform(poseOf(base));
  for (int k = 0; k < n; ++k) {
    const scene::ArticulatedLink& l = a.links[k];
    const scene::Body& parent = s.bodies[l.parent < 0 ? a.base : a.links[l.parent].body];
    const scene::Joint& j = s.joints[l.joint];
    setupLink(mb, k, l.parent, s.bodies[l.body], j,
              framesOf(poseOf(parent), poseOf(s.bodies[l.body]), j));
  }
  mb.finalizeMultiDof();
  // The scene has no damping; btMultiBody's default (0.04) would slow it against "bullet" and ODE.
  mb.setLinearDamping(0);
  mb.setAngularDamping(0);
  mb.setHasSelfCollision(true);
  auto& world = static_cast<btMultiBodyDynamicsWorld&>(*world_);
  world.addMultiBody(&mb);

  mb.setBaseCollider(addCollider(s, base, &mb, -1));
  linkOf_[a.base] = {&mb, -1};
  for (int k = 0; k < n; ++k) {
    const scene::ArticulatedLink& l = a.links[k];
    mb.getLink(k).m_collider = addCollider(s, s.bodies[l.body], &mb, k);
    linkOf_[l.body] = {&mb, k};
    const scene::Joint& j = s.joints[l.joint];
    if (j.limits.enabled)
      multiBodyConstraints_.push_back(std::make_unique<btMultiBodyJointLimitConstraint>(
          &mb, k, j.limits.lower, j.limits.upper));
    if (j.motor.enabled)
      multiBodyConstraints_.push_back(std::make_unique<btMultiBodyJointMotor>(
          &mb, k, j.motor.velocity, j.motor.maxForce * timeStep_));
  }
  for (auto& c : multiBodyConstraints_)
    if (c->getMultiBodyA() == &mb) world.addMultiBodyConstraint(c.get());
  btAlignedObjectArray<btQuaternion> rotations;
  btAlignedObjectArray<btVector3> origins;
  mb.updateCollisionObjectWorldTransforms(rotations, origins);
}

std::vector<scene::BodyState> BulletScene::states() const {
  std::vector<scene::BodyState> out(bodyPointers_.size());
  auto fill = [](scene::BodyState& st, const btTransform& t, const btVector3& v,
                 const btVector3& w) {
    const btQuaternion q = t.getRotation();
    st.position = vec(t.getOrigin());
    st.orientation = {q.w(), q.x(), q.y(), q.z()};
    st.velocity = vec(v);
    st.angularVelocity = vec(w);
  };
  for (std::size_t i = 0; i < bodyPointers_.size(); ++i)
    if (const btRigidBody* b = bodyPointers_[i])
      fill(out[i], b->getCenterOfMassTransform(), b->getLinearVelocity(), b->getAngularVelocity());
  // btMultiBody bodies: link velocities in each link's frame (compTreeLinkVelocities), turned
  // into the world by the link's collider pose (which the world updates after every step).
  std::vector<btVector3> omega, velocity;
  for (std::size_t i = 0; i < linkOf_.size(); ++i) {
    const auto [mb, link] = linkOf_[i];
    if (!mb) continue;
    omega.assign(mb->getNumLinks() + 1, btVector3(0, 0, 0));
    velocity.assign(mb->getNumLinks() + 1, btVector3(0, 0, 0));
    mb->compTreeLinkVelocities(omega.data(), velocity.data());
    const btCollisionObject* c = link < 0 ? mb->getBaseCollider() : mb->getLinkCollider(link);
    const btTransform& t = c->getWorldTransform();
    fill(out[i], t, t.getBasis() * velocity[link + 1], t.getBasis() * omega[link + 1]);
  }
  return out;
}

}  // namespace mlcp::bullet
