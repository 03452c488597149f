#include "bullet_drop.hpp"

#include <btBulletDynamicsCommon.h>

#include <memory>
#include <mlcp/bullet/constraint_solver.hpp>

BulletDrop bulletDrop(const char* solverName) {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  mlcp::bullet::Settings settings;
  settings.solver = solverName;
  mlcp::bullet::ConstraintSolver solver(settings);
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(btVector3(0, -9.81, 0));

  btBoxShape groundShape(btVector3(5, 0.5, 5));
  btRigidBody ground(0, nullptr, &groundShape);
  ground.setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, -0.5, 0)));
  world.addRigidBody(&ground);

  btBoxShape boxShape(btVector3(0.5, 0.5, 0.5));
  btVector3 inertia;
  boxShape.calculateLocalInertia(1, inertia);
  btDefaultMotionState motion(btTransform(btQuaternion::getIdentity(), btVector3(0, 0.7, 0)));
  btRigidBody box(btRigidBody::btRigidBodyConstructionInfo(1, &motion, &boxShape, inertia));
  box.setActivationState(DISABLE_DEACTIVATION);
  world.addRigidBody(&box);

  BulletDrop out;
  for (int i = 0; i < 120; ++i) {
    world.stepSimulation(1.0 / 60, 1, 1.0 / 60);
    out.solvedIslands += solver.lastStep().islands;
    if (!(solver.lastStep().residual <= out.worstResidual))
      out.worstResidual = solver.lastStep().residual;
  }
  out.height = box.getWorldTransform().getOrigin().y();
  out.speed = box.getLinearVelocity().length();
  world.removeRigidBody(&box);
  world.removeRigidBody(&ground);
  return out;
}
