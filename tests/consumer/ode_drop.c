#include "ode_drop.h"

#include <math.h>

struct drop {
  dWorldID world;
  dJointGroupID contacts;
};

static void near_callback(void* data, dGeomID a, dGeomID b) {
  struct drop* d = (struct drop*)data;
  dContact contact[4];
  int n = dCollide(a, b, 4, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) {
    contact[i].surface.mode = dContactApprox1;
    contact[i].surface.mu = 0.5;
    dJointID j = dJointCreateContact(d->world, d->contacts, &contact[i]);
    dJointAttach(j, dGeomGetBody(contact[i].geom.g1), dGeomGetBody(contact[i].geom.g2));
  }
}

double ode_drop_run(ode_drop_step_fn step, void* context, double* speed) {
  dInitODE2(0);
  struct drop d;
  d.world = dWorldCreate();
  d.contacts = dJointGroupCreate(0);
  dWorldSetGravity(d.world, 0, 0, -9.81);
  dSpaceID space = dHashSpaceCreate(0);
  dCreatePlane(space, 0, 0, 1, 0);
  dBodyID body = dBodyCreate(d.world);
  dMass m;
  dMassSetSphereTotal(&m, 1.0, 0.5);
  dBodySetMass(body, &m);
  dBodySetPosition(body, 0, 0, 0.7);
  dGeomSetBody(dCreateSphere(space, 0.5), body);

  int ok = 1;
  for (int i = 0; i < 150 && ok; ++i) {
    dSpaceCollide(space, &d, &near_callback);
    ok = step(context, d.world, 0.01);
    dJointGroupEmpty(d.contacts);
  }
  const dReal* p = dBodyGetPosition(body);
  const dReal* v = dBodyGetLinearVel(body);
  const double height = p[2];
  *speed = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  dJointGroupDestroy(d.contacts);
  dSpaceDestroy(space);
  dWorldDestroy(d.world);
  dCloseODE();
  return ok ? height : -1;
}
