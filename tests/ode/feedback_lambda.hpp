// A joint's constraint forces recovered from its dJointFeedback, for the tests and benchmarks
// that measure a stepper whose multipliers are not returned (dWorldQuickStep) on the MLCP our
// stepper keeps (Settings::keepProblems).
//
// ODE's steppers (dxStepIsland, dxQuickStepIsland's stage 4b) and ours write, per joint with m
// rows, f1 t1 = J_1^T lambda and f2 t2 = J_2^T lambda, where J_1, J_2 are the rows' 6-wide
// blocks on the joint's first and second body (f2 t2 only with a second body) and lambda the
// rows' constraint forces (QuickStep: its SOR's lambda, J copied before the SOR scales the rows
// by omega / A_ii; ours: the applied x). Given the joint's rows, lambda is the least-squares
// solution of
//
//     [J_1; J_2]^T lambda = [f1; t1; f2; t2],
//
// exact when the rows are linearly independent (a contact's normal and two friction rows have
// orthonormal linear parts; a hinge's ball rows have an identity linear part), which the fit's
// residual shows.
#pragma once

#include <ode/ode.h>

#include <Eigen/Dense>

#include "mlcp/rows.hpp"

namespace mlcp::ode::test {

// Writes the forces of rows first .. first + count - 1 of `rows` (one joint's) into the same
// entries of lambda, from that joint's feedback. Returns the fit's residual
// ||J^T lambda - f||_inf / (1 + ||f||_inf).
inline double lambdaFromFeedback(const RowSystem& rows, int first, int count,
                                 const dJointFeedback& fb, Vector& lambda) {
  const bool twoBodies = rows.rows[first].bodyB >= 0;
  const int n = twoBodies ? 12 : 6;
  Eigen::MatrixXd jt(n, count);
  Eigen::VectorXd f(n);
  for (int k = 0; k < count; ++k) {
    jt.col(k).head<6>() = rows.rows[first + k].jA;
    if (twoBodies) jt.col(k).tail<6>() = rows.rows[first + k].jB;
  }
  for (int k = 0; k < 3; ++k) {
    f[k] = fb.f1[k];
    f[3 + k] = fb.t1[k];
    if (twoBodies) {
      f[6 + k] = fb.f2[k];
      f[9 + k] = fb.t2[k];
    }
  }
  const Eigen::VectorXd l = jt.completeOrthogonalDecomposition().solve(f);
  lambda.segment(first, count) = l;
  return (jt * l - f).lpNorm<Eigen::Infinity>() / (1 + f.lpNorm<Eigen::Infinity>());
}

}  // namespace mlcp::ode::test
