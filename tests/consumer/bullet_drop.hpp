// A 1 m box dropped from 0.2 m onto a ground box in a stock btDiscreteDynamicsWorld whose
// constraint solver is mlcp::bullet::ConstraintSolver with the named core solver; 120 steps of
// 1/60 s.
#pragma once

struct BulletDrop {
  double height = 0;         // of the box's centre at the end, m (0.5 at rest)
  double speed = 0;          // m/s at the end
  double worstResidual = 0;  // over the steps' islands
  int solvedIslands = 0;     // summed over the steps
};

BulletDrop bulletDrop(const char* solverName);
