// What the Bullet scene loader's files (scene_loader.cpp, scene_multibody.cpp) share: the
// conversions between the scene's values and Bullet's, and the scene's material rule. Internal.
#pragma once

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <utility>
#include <vector>

#include "mlcp/scene/scene.hpp"

namespace mlcp::bullet {

inline btVector3 bt(const scene::Vec3& v) { return btVector3(v[0], v[1], v[2]); }
inline scene::Vec3 vec(const btVector3& v) { return {v.x(), v.y(), v.z()}; }
inline btQuaternion bt(const scene::Quat& q) { return btQuaternion(q.x, q.y, q.z, q.w); }

// The body's pose at creation: its centre of mass and orientation in the world.
inline btTransform poseOf(const scene::Body& b) {
  return btTransform(bt(b.orientation), bt(b.position));
}

// Friction sqrt(mu), which Bullet multiplies into the scene's sqrt(mu_a mu_b); restitution e,
// combined by max through the callback the loader installs.
inline void setMaterial(btCollisionObject& o, const scene::Material& m) {
  o.setFriction(std::sqrt(m.friction));
  o.setRestitution(m.restitution);
}

// The scene's fixed-base neighbours (Scene::fixedBaseNeighbours) never collide; `objects` holds
// each scene body's collision object (nullptr where it has none).
inline void ignoreFixedBaseContacts(const scene::Scene& s,
                                    const std::vector<btCollisionObject*>& objects) {
  for (const auto& [a, b] : s.fixedBaseNeighbours()) {
    if (!objects[a] || !objects[b]) continue;
    objects[a]->setIgnoreCollisionCheck(objects[b], true);
    objects[b]->setIgnoreCollisionCheck(objects[a], true);
  }
}

}  // namespace mlcp::bullet
