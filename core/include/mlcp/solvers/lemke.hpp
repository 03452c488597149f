// mlcp/solvers/lemke.hpp: Lemke's complementary pivoting (registry "lemke") and its tableau trace.
//
// The standard LCP w = M z + q, w, z >= 0, w'z = 0 gets an artificial z0 with a column of ones
// (Cottle, Pang and Stone, The Linear Complementarity Problem, 4.4):
//
//     w - M z - e z0 = q,   tableau [ I | -M | -e | q ],   basis w at the start.
//
// q >= 0 is the answer (w, z) = (q, 0). Otherwise z0 enters at the most negative q_i; then the
// complement of the variable that just left enters, at the row the minimum-ratio test picks,
// ties broken by the lexicographic rule (rows of [rhs, B^-1] / pivot entry: no cycling). It ends
// when z0 leaves (complementary basis: the answer) or when the entering column has no positive
// entry (ray termination: Status::Failed). Invariants: basic values >= 0; the basis holds z0
// and one of w_i, z_i for every i but one. Guarantees: a P-matrix M is solved for every q; a
// copositive-plus M (PSD, linear programs) whenever the LCP is feasible, a ray then proving it
// infeasible; other M may end on a ray although a solution exists.
//
// Our form (problem.hpp) becomes the standard one by a change of variables (m >= n rows): fixed
// and narrower-than-round-off rows substituted; x = lo + z for [lo, inf), x = hi - z for
// (-inf, hi]; a finite box as x = lo + z1 with z2 = max(-w, 0), rows w + z2 and hi - lo - z1;
// free rows eliminated by the Schur complement of a regular A_FF (tableau path) or split as
// x = z+ - z-. PSD A gives PSD M. The final active set is re-solved in the original problem (LU
// or KLU, one refinement step) and the better of the two answers kept.
//
// Cost: the dense tableau (core/src/pivoting/lemke_tableau.hpp) holds m x (2m + 2) doubles, a
// pivot O(m^2); the factored basis (lemke_revised.hpp: KLU of B and an eta file, M sparse) holds
// O(nnz(M) + nnz(L + U) + period m), a pivot O(nnz(L + U) + period m). Murty's examples take
// 2^m - 1 pivots. Limits: Options::maxPivots (0: 50 m + 100) bounds the whole solve, friction
// passes together (MaxIterations); Options::timeBudget stops it between pivots (TimeLimit); the
// start or the last pass's answer is then returned, never a half-pivoted tableau.
//
// Singular A (redundant joints) ends on a ray in floating point: the solve runs once more from the
// same start on A + delta I, delta = kLemkeRayShift max(1, max |A_ii|), and the answer with the
// lower residual on A stands ("regularised"). Friction (findex): by default one LCP, each tangent
// row written as l+ - l- with a slack (the Stewart-Trinkle / Anitescu-Potra box form,
// core/src/pivoting/box_friction_lcp.hpp), which needs no fixed point (on the factored basis its
// pivots are tested at 100x Options::pivotTolerance); its answer's active set is re-solved in the
// original problem. When it ends short (a ray, or z0 out at values above the tolerance), it runs
// once more on the dense tableau if it was factored (up to 500 rows), then the fixed point from the
// start, within one pivot limit. The fixed point (frictionLcp = false, or a normal row whose bounds
// straddle 0): each pass a boxed LCP on the bounds of the previous answer, its active set re-solved
// with the true coupled bounds; a guess only seeds those bounds. Details: docs/methods/pivoting.md,
// the "Lemke: ..." sections (the standard form, the choice by size, the friction passes, friction
// as one LCP).
#pragma once

#include <iosfwd>
#include <string>

#include "mlcp/solver.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

class LemkeSolver : public Solver {
 public:
  const char* name() const override { return "lemke"; }
  // Problems of up to this many rows pivot on the dense tableau, larger ones on the factored
  // basis (docs/methods/pivoting.md, "Lemke: tableau or factored basis"); problems with free
  // rows keep the tableau up to kLemkeFreeRowsTableauRows (2000, thresholds.hpp). Default
  // kLemkeTableauRows (50).
  int denseRows = kLemkeTableauRows;
  // Factored basis: pivots between two factorizations of the basis matrix (halved when the
  // updated basic values lose accuracy). Default 50.
  int refactorPeriod = 50;
  // Largest problem accepted, in rows (Status::Unsupported above it, x untouched). Default
  // 5,000,000.
  int maxRows = 5000000;
  // Friction (findex) as one LCP in l+, l- and a slack per tangent row (box_friction_lcp.hpp),
  // the fixed point only after it ends short; false: the fixed point alone. Default true.
  bool frictionLcp = true;

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  // The pivoting on A, the problem's matrix or a regularised one: friction as one LCP when
  // frictionLcp and the problem fits it, otherwise pivotPasses.
  void pivot(const Problem& problem, const SparseMatrix& A, Vector& x, Result& result);
  // The standard form's pivoting, with the friction passes when the problem has findex; the
  // dense tableau up to tableauRows rows; pivots tested at pivotScale x Options::pivotTolerance.
  void pivotPasses(const Problem& problem, const SparseMatrix& A, Vector& x, Result& result,
                   int tableauRows, double pivotScale = 1);
};

// Runs Lemke on a standard LCP (lo = 0, hi = +inf, no findex) and prints every tableau to out:
// the column labels w1..wn z1..zn z0 | q, one row per basic variable, and before each table
// the pivot that produced it ("pivot 2: z2 enters, w1 leaves (row 1)"). Entries are exact
// fractions when every entry of A and b is an integer (64-bit fractions; if one would overflow
// the trace restarts in decimals and says so), decimals otherwise. Uses options.maxPivots and
// options.tolerance. Returns the outcome like a solver would (status, pivots in iterations,
// message, accuracy of the answer) and stores the answer in *x when x is given. Other problem
// classes are refused with Status::Unsupported and a message, printing nothing.
Result traceLemke(const Problem& problem, std::ostream& out, const Options& options = Options(),
                  Vector* x = nullptr);

}  // namespace mlcp
