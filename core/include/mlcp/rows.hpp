// mlcp/rows.hpp: constraint rows in the factored form physics engines hand over.
//
// Engines do not build A. They give, per constraint row i, two 6-wide Jacobian blocks
// J_iA, J_iB (linear part first, then angular) on two bodies A and B, and per body its
// inverse mass and world-frame inverse inertia. With M^-1 the block-diagonal inverse mass
// matrix, the MLCP is
//
//     w = (J M^-1 J^T + diag(cfm)) x + b,   lo <= x <= hi,   findex as in problem.hpp,
//
// in the canonical form of problem.hpp (engines' rhs is -b: the adapters convert). Keeping
// this form lets PGS run on rows and body velocities with O(nnz J) work per sweep and no A at
// all (RowPgs below); pivoting methods get A from assemble(), sparse by the body graph (only
// rows sharing a body couple), dense only when asked.
//
// Bodies with invMass == 0 and a zero invInertia are static; a row's body index -1 means "the
// world" (its block is ignored).
//
// Articulated bodies (a Featherstone multibody: base and joint velocities in one vector of
// width 6 + ndof) have no block-diagonal M^-1 an engine hands over; it gives, per row side, J
// and W = M^-1 J^T (Bullet's m_jacobians and m_deltaVelocitiesUnitImpulse). A row may have,
// besides its rigid bodies, one ArticulatedSide per articulated body it touches (an engine row
// with the same body on both sides passes J_A + J_B and W_A + W_B as one side). Then
// A_ij = sum over shared rigid bodies J_i M^-1 J_j^T + sum over shared articulated bodies
// J_j . W_i + [i == j] cfm_i: W_i = M^-1 J_i^T makes it symmetric, as the rigid part is.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "mlcp/problem.hpp"
#include "mlcp/residual.hpp"
#include "mlcp/result.hpp"

namespace mlcp {

using Vector6 = Eigen::Matrix<double, 6, 1>;

struct BodyInverseMass {
  double invMass = 0;                                    // 1 / mass, 0 for static bodies
  Eigen::Matrix3d invInertia = Eigen::Matrix3d::Zero();  // world frame
};

struct ConstraintRow {
  int bodyA = -1, bodyB = -1;    // indices into RowSystem::bodies, -1 = world
  Vector6 jA = Vector6::Zero();  // [linear; angular] Jacobian on body A
  Vector6 jB = Vector6::Zero();  // [linear; angular] Jacobian on body B
};

// One row's part on one articulated body: J at jacobian[at .. at + width) and W = M^-1 J^T at
// unitImpulse[at .. at + width), width = RowSystem::articulated[body].
struct ArticulatedSide {
  int row = -1;   // index into RowSystem::rows
  int body = -1;  // index into RowSystem::articulated
  int at = 0;     // offset into RowSystem::jacobian and RowSystem::unitImpulse
};

class RowSystem {
 public:
  std::vector<BodyInverseMass> bodies;
  std::vector<ConstraintRow> rows;
  Vector b, lo, hi, cfm;    // per row; cfm >= 0 is added to A's diagonal
  std::vector<int> findex;  // per row or empty
  // Articulated bodies (see above): each one's velocity width (> 0), the row sides on them (any
  // order) and their J and W, stored flat. Empty for rigid-only systems.
  std::vector<int> articulated;
  std::vector<ArticulatedSide> sides;
  std::vector<double> jacobian, unitImpulse;
  bool hasArticulated() const { return !sides.empty(); }

  int size() const { return static_cast<int>(rows.size()); }
  // "" when well formed, otherwise the first thing wrong (sizes, body indices, NaN/Inf, and
  // every rule of Problem::validate for b, lo, hi, findex).
  std::string validate() const;

  // A = J M^-1 J^T + diag(cfm) with the bounds copied: the same MLCP as a Problem.
  Problem assemble(bool sparse) const;
  // The same into `into`, reusing its vectors, A's storage (Problem::swapA) and the scratch's
  // buffers: a per-step caller (RowSolver) allocates nothing once the sizes have been seen.
  // Sparse A: a new pattern is written row by row in place (each row the merge of its bodies'
  // row lists, O(nnz A), no sort) and remembered; when the rows join the same bodies as in the
  // last sparse assembly with this scratch and `into` still holds that pattern (index arrays
  // compared), only the values are written, through each product's slot (found once per
  // pattern, at its second assembly: islands whose contacts change every step never pay for
  // it). Both sum in the dense path's order: the same bits in every storage.
  // The buffers and the remembered pattern of the call above (core/src/rows.cpp),
  // opaque here: one per island that is assembled every step.
  class AssembleScratch {
   public:
    AssembleScratch();
    AssembleScratch(AssembleScratch&&) noexcept;
    AssembleScratch& operator=(AssembleScratch&&) noexcept;
    ~AssembleScratch();
    struct Buffers;

   private:
    friend class RowSystem;
    std::unique_ptr<Buffers> buffers_;
  };
  void assemble(bool sparse, Problem& into, AssembleScratch& scratch) const;
  // w = A x + b computed through body velocities, O(nnz J).
  Vector slack(const Vector& x) const;
  // The same into w, from the body velocities v = bodyVelocities(x) the caller already holds
  // (a per-island caller reuses both buffers: no allocation once the sizes have been seen).
  void slack(const Vector& x, const std::vector<Vector6>& v, Vector& w) const;
  // e(x) = 1/2 x^T A x = 1/2 x^T (w - b), O(nnz J): the kinetic energy of the velocity change
  // M^-1 J^T x the impulses make (plus the cfm's share), whatever the bodies' velocities. An
  // exploded answer (impulses along nearly dependent rows, 1e9 times a drifted loop's error)
  // shows as an e many orders above a sane one's.
  double impulseEnergy(const Vector& x) const;
  // Body velocity changes M^-1 J^T x, 6 per body ([linear; angular]).
  std::vector<Vector6> bodyVelocities(const Vector& x) const;
  // The same into v (resized to bodies.size(), its storage reused).
  void bodyVelocities(const Vector& x, std::vector<Vector6>& v) const;
  // Articulated velocity changes sum_i W_i x_i, per articulated body its `articulated[k]`
  // entries, concatenated in body order.
  Vector articulatedVelocities(const Vector& x) const;
  // The largest |entry| of articulatedVelocities(x) over base linear velocities (entries 3..5,
  // Bullet's order: base angular, base linear, joints) and joint rates; 0 without articulated
  // bodies. RowSolver's speed guard reads it beside the rigid bodies' linear speeds.
  double articulatedSpeed(const Vector& x) const;
};

}  // namespace mlcp
