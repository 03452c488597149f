// mlcp/solvers/lemke.hpp: Lemke's complementary pivoting method (registry "lemke") and its tableau
// trace.
//
// The method (the seed notes, section 1; Cottle, Pang and Stone, The Linear Complementarity
// Problem, section 4.4). For the standard LCP w = M z + q, w, z >= 0, w'z = 0, add an
// artificial variable z0 with a column of ones, w - M z - e z0 = q, and keep the tableau
//
//     [ I | -M | -e | q ]        basis w, columns w_1..w_n, z_1..z_n, z_0.
//
// 1. If q >= 0, (w, z) = (q, 0) solves the problem (no pivot).
// 2. Otherwise z0 enters at the row of the most negative q; every basic value is then >= 0.
// 3. The entering variable is the complement of the one that just left. If its column has no
//    positive entry the method stops with ray termination (Status::Failed). Otherwise the
//    minimum-ratio test picks the leaving row and a Gauss-Jordan pivot exchanges the two.
// 4. When z0 leaves, the basis is complementary and the table holds a solution.
//
// Degeneracy: ties of the ratio test are broken by the lexicographic rule (rows of
// [rhs, B^-1] divided by the pivot entry; B^-1 sits in the w-columns), which is equivalent to
// perturbing q by (eps, eps^2, ..., eps^n) and makes cycling impossible, so the method always
// ends after finitely many pivots. z0's row wins every tie of the plain ratio (it ends the
// method at once).
//
// When it works. For a P-matrix M (e.g. symmetric positive definite) Lemke finds the unique
// solution for every q. For a copositive-plus M (e.g. positive semidefinite, and the
// [[0, A'], [-A, 0]] matrices of linear programs) it finds a solution whenever the LCP is
// feasible, and ray termination then proves infeasibility. For other matrices (bimatrix games,
// general indefinite M) it may end on a ray although a solution exists. Murty's examples take
// 2^n - 1 pivots; the pivot limit is Options::maxPivots, 0 meaning 50 m + 100 for an LCP of
// size m, counted over the whole solve (every friction iteration below together; Status::
// MaxIterations when reached), and Options::timeBudget stops it between pivots
// (Status::TimeLimit); either way the message says so and the start (or, with friction, the
// last outer iteration's answer) is returned, never a half-pivoted tableau.
//
// Two implementations of the same pivots, chosen by size (LemkeSolver::denseRows):
//   - Dense tableau (lemke_tableau.hpp): m x (2m + 2) doubles, a Gauss-Jordan pivot of O(m^2).
//     The trace (traceLemke) always uses it, in exact fractions where it can.
//   - Factored basis (lemke_revised.hpp), the revised method: the tableau is B^-1 [I, -M, -e | q]
//     with B the basis matrix (the columns of the basic variables), so only B is kept, as a KLU
//     factorization of the last refactorization times an eta file (product form: one column
//     d = B^-1 a per pivot since then). A pivot solves B d = a for the entering column a, does
//     the ratio test on d and x_B, and moves x_B by the ratio step. The lexicographic rule reads
//     rows of B^-1 only for rows tied in the plain ratio, by solves B' r = e_i. Invariants:
//     x_B = B^-1 q >= 0 up to round-off; the basis holds one of w_i, z_i for every i but one
//     (and z0) until z0 leaves. Every LemkeSolver::refactorPeriod pivots B is factored again and
//     x_B recomputed from q; a drift of the updated x_B above 1e-9 (relative) halves the period.
//     M stays sparse (never an n x n dense array): memory O(nnz(M) + nnz(L + U) + period m), a
//     pivot O(nnz(L + U) + period m) plus one solve with B' per tied row.
// Choice by size: problems of up to denseRows rows (default 50) use the tableau, larger ones the
// factored basis, except problems with free rows of up to kLemkeFreeRowsTableauRows (2000) rows:
// the tableau eliminates their free rows by a dense Schur complement where the free block is
// regular, and where it is singular retries on A + delta I; split into z+ - z- on the factored
// basis, the singular bilateral islands of a plank bridge (78 rows, ODE) end on a ray. The
// crossover is measured by tests/bench/lemke_bench.cpp (docs/benchmarks.md): on dense SPD matrices
// the two are even at ~30 rows and the factored basis is ahead from ~100; on banded ones it is
// ahead from ~100 rows and by 60x at 1000. KLU because it is the project's sparse LU
// (linalg/sparse_lu.hpp), factors an unsymmetric B with threshold pivoting and keeps no BLAS state;
// UMFPACK is not measured here. Problems above maxRows are refused (Status::Unsupported, x
// untouched).
//
// Accuracy. Pivoting is for complementarity, not for stability, so the final values carry
// round-off. The solver therefore re-solves the final active set in the original problem, the
// n x n system "w_i = 0 for rows strictly inside their bounds, x_i = bound for the others", with
// a dense LU (partial pivoting; tableau path) or KLU (factored path) plus one step of iterative
// refinement, and returns whichever of the two answers has the smaller residual.
//
// Problems that are not standard LCPs become one by a change of variables (m >= n rows):
//   - lo_i == hi_i (fixed):       x_i = lo_i, substituted into b; the row leaves the LCP. So does
//                                 a box narrower than 1e-13 times the scale of x (the largest
//                                 finite |bound| or ||b|| / max|A_ij|): x_i = lo_i.
//   - [lo, +inf):                 x = lo + z, z >= 0 complementary to w.
//   - (-inf, hi]:                 x = hi - z, z >= 0 complementary to -w.
//   - [lo, hi], both finite:      x = lo + z1 and the negative part of w, z2 = max(-w, 0):
//                                 z1 >= 0 complementary to  w + z2 >= 0,
//                                 z2 >= 0 complementary to  hi - lo - z1 >= 0.
//     (x inside: z2 = 0 and w = 0; x = lo: w >= 0; x = hi: w = -z2 <= 0.)
//   - (-inf, +inf) (equality):    tableau path: eliminated by the Schur complement when the
//                                 block A_FF of free rows is nonsingular: x_F = -A_FF^-1 (b_F +
//                                 A_FK x_K), leaving A_KK - A_KF A_FF^-1 A_FK (SPD stays SPD, a
//                                 P-matrix stays a P-matrix). Otherwise x = z+ - z-, both >= 0,
//                                 with complementary rows w >= 0 and -w >= 0 (always so on the
//                                 factored path, whose M stays as sparse as A).
// The transformed matrix is positive semidefinite when A is, so the guarantees above carry over
// for PSD A; for a P-matrix A with finite boxes the doubled matrix is no longer a P-matrix and
// ray termination, though not expected, is reported as it is.
//
// Singular A. In exact arithmetic a feasible LCP with PSD M never ends on a ray; in floating
// point a singular A (engines' redundant joints: a pair of ball joints on one axis) does, its
// zero pivots rounded to either sign. A solve that ends on a ray runs once more from the same
// start on A + delta I, delta = 1e-12 max(1, max |A_ii|), and the answer with the lower residual
// on A itself stands (the message says "regularised"). A consistent singular problem keeps a
// residual of order delta ||x|| on A; an infeasible one ends on a ray again.
//
// Friction (findex) rows: an outer fixed point on the bounds. Iteration k solves the boxed
// problem with bounds lo_i |x_j|, hi_i |x_j| taken from the previous answer (from the start
// point, zero unless a guess is given, at k = 1), then re-solves its active set with the true
// coupled bounds (x_i = +-mu_i |x_j| as linear equations). It stops when the residual with the
// true bounds is within Options::tolerance (Converged), when the bounds stop moving above the
// tolerance (Failed), or after Options::maxIterations outer steps (MaxIterations). The fixed
// point need not converge (large mu, strongly coupled contacts); the status then says so.
// Result::iterations counts pivots over all outer steps, and the one pivot limit bounds them
// together, so a solve costs at most maxPivots pivots whatever the passes do. On the factored
// path each pass after the first starts from the previous pass's final basis (each LCP variable,
// keyed by its row and role, basic as it was), with the covering vector B0 e in place of e so
// that z0's column reads -e in that basis; it need not be positive, which voids Lemke's
// guarantees, so a warm attempt that ends on a ray, a singular basis or half its pivot share is
// followed by a cold start from the slack basis. When the passes run out the message gives the
// last pass's largest relative move of a bound.
//
// Warm start: a guess only seeds the friction bounds; the first pass starts from the slack basis.
#pragma once

#include <iosfwd>

#include "mlcp/solver.hpp"
#include "mlcp/thresholds.hpp"

namespace mlcp {

class LemkeSolver : public Solver {
 public:
  const char* name() const override { return "lemke"; }
  // Problems of up to this many rows pivot on the dense tableau, larger ones on the factored
  // basis (see "Choice by size" above); problems with free rows keep the tableau up to
  // kLemkeFreeRowsTableauRows (2000, thresholds.hpp). Default kLemkeTableauRows (50).
  int denseRows = kLemkeTableauRows;
  // Factored basis: pivots between two factorizations of the basis matrix (halved when the
  // updated basic values drift). Default 50.
  int refactorPeriod = 50;
  // Largest problem accepted, in rows (Status::Unsupported above it, x untouched). Default
  // 5,000,000.
  int maxRows = 5000000;

 protected:
  void run(const Problem& problem, Vector& x, Result& result) override;

 private:
  // The pivoting (with the friction passes) on A, the problem's matrix or a regularised one.
  void pivot(const Problem& problem, const SparseMatrix& A, Vector& x, Result& result);
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
