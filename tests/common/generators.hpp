// Test problems with known solutions, shared by every test suite.
//
// A problem with a known solution is built backwards: pick A, the bounds and a complementary
// pair (x*, w*) (each row at its lower bound with w >= 0, at its upper bound with w <= 0, or
// strictly inside with w = 0), then set b = w* - A x*. For a P-matrix (e.g. SPD) A the
// solution of a boxed problem is unique, so solvers can be checked against x* as well as by
// the residual.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "mlcp/problem.hpp"

namespace mlcp::test {

struct KnownProblem {
  std::string name;
  Problem problem;
  Vector solution;      // x*
  bool unique = false;  // whether x* is the only solution
};

class Generator {
 public:
  explicit Generator(unsigned seed) : rng_(seed) {}

  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }

  // SPD: B B^T + n * shift * I with B uniform in [-1, 1].
  DenseMatrix spd(int n, double shift = 0.1) {
    DenseMatrix B(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) B(i, j) = uniform(-1, 1);
    return B * B.transpose() + n * shift * DenseMatrix::Identity(n, n);
  }

  // Rank-deficient PSD: J J^T with J n x r, r < n (like 4 contact points of one box).
  DenseMatrix psdSingular(int n, int rank) {
    DenseMatrix J(n, rank);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < rank; ++j) J(i, j) = uniform(-1, 1);
    return J * J.transpose();
  }

  // Standard LCP (lo = 0, hi = inf) with a random active pattern. degenerate: some rows get
  // x* = 0 and w* = 0 at once (weakly active ties).
  KnownProblem standard(DenseMatrix A, bool degenerate = false) {
    const int n = static_cast<int>(A.rows());
    Vector lo = Vector::Zero(n), hi = Vector::Constant(n, kInf);
    Vector x(n), w(n);
    for (int i = 0; i < n; ++i) {
      const bool tie = degenerate && pick(3) == 0;
      if (tie) {
        x[i] = 0;
        w[i] = 0;
      } else if (pick(2) == 0) {
        x[i] = uniform(0.1, 2);
        w[i] = 0;
      } else {
        x[i] = 0;
        w[i] = uniform(0.1, 2);
      }
    }
    return finish("standard", std::move(A), lo, hi, {}, x, w);
  }

  // Boxed rows of every kind: finite boxes (x at lo, at hi or inside), equality rows,
  // half-infinite rows.
  KnownProblem boxed(DenseMatrix A) {
    const int n = static_cast<int>(A.rows());
    Vector lo(n), hi(n), x(n), w(n);
    for (int i = 0; i < n; ++i) {
      switch (pick(4)) {
        case 0:  // equality row
          lo[i] = -kInf;
          hi[i] = kInf;
          x[i] = uniform(-2, 2);
          w[i] = 0;
          break;
        case 1:  // (-inf, hi]
          lo[i] = -kInf;
          hi[i] = uniform(-1, 1);
          placeBox(lo[i], hi[i], x[i], w[i]);
          break;
        default:  // finite box
          lo[i] = uniform(-2, 0);
          hi[i] = lo[i] + uniform(0.5, 2);
          placeBox(lo[i], hi[i], x[i], w[i]);
          break;
      }
    }
    return finish("boxed", std::move(A), lo, hi, {}, x, w);
  }

  // Equality rows only: a linear system A x + b = 0.
  KnownProblem linear(DenseMatrix A) {
    const int n = static_cast<int>(A.rows());
    Vector x(n);
    for (int i = 0; i < n; ++i) x[i] = uniform(-2, 2);
    return finish("linear", std::move(A), Vector::Constant(n, -kInf), Vector::Constant(n, kInf), {},
                  x, Vector::Zero(n));
  }

  // Contacts with friction: triples (normal, t1, t2), findex of t1, t2 -> normal, mu in
  // [0.2, 1]. Each contact is separating (x_n = 0), sticking (|x_t| < mu x_n) or sliding on
  // one friction bound. A from J M^-1 J^T-like SPD.
  KnownProblem friction(int contacts, double shift = 0.1) {
    const int n = 3 * contacts;
    DenseMatrix A = spd(n, shift);
    Vector lo(n), hi(n), x(n), w(n);
    std::vector<int> findex(n, -1);
    for (int c = 0; c < contacts; ++c) {
      const int k = 3 * c;
      const double mu = uniform(0.2, 1);
      lo[k] = 0;
      hi[k] = kInf;
      const int mode = pick(3);
      x[k] = mode == 0 ? 0 : uniform(0.5, 2);
      w[k] = mode == 0 ? uniform(0.1, 1) : 0;
      for (int t = 1; t <= 2; ++t) {
        findex[k + t] = k;
        lo[k + t] = -mu;
        hi[k + t] = mu;
        const double bound = mu * x[k];
        if (mode == 0) {  // no normal force: friction bounds are [0, 0]
          x[k + t] = 0;
          w[k + t] = uniform(-1, 1);
        } else if (mode == 1) {  // sticking
          x[k + t] = uniform(-0.5, 0.5) * bound;
          w[k + t] = 0;
        } else {  // sliding on a bound
          const bool up = pick(2) == 0;
          x[k + t] = up ? bound : -bound;
          w[k + t] = up ? -uniform(0.1, 1) : uniform(0.1, 1);
        }
      }
    }
    KnownProblem kp = finish("friction", std::move(A), lo, hi, findex, x, w);
    kp.unique = false;  // findex problems need not have unique solutions
    return kp;
  }

 private:
  void placeBox(double lo, double hi, double& x, double& w) {
    const int where = std::isfinite(lo) ? pick(3) : 1 + pick(2);
    if (where == 0) {
      x = lo;
      w = uniform(0.1, 2);
    } else if (where == 1) {
      x = hi;
      w = -uniform(0.1, 2);
    } else {
      x = std::isfinite(lo) ? uniform(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo))
                            : hi - uniform(0.1, 1);
      w = 0;
    }
  }

  KnownProblem finish(const char* name, DenseMatrix A, const Vector& lo, const Vector& hi,
                      std::vector<int> findex, const Vector& x, const Vector& w) {
    KnownProblem kp;
    kp.name = name;
    kp.problem.b = w - A * x;
    kp.problem.setA(std::move(A));
    kp.problem.lo = lo;
    kp.problem.hi = hi;
    kp.problem.findex = std::move(findex);
    kp.solution = x;
    kp.unique = true;
    return kp;
  }

  std::mt19937 rng_;
};

// The worked Lemke example (a 3-row LCP solved by hand, tableau by tableau): x = (20/19, 21/19, 0),
// w = (0, 0, 12/19).
inline Problem seedLemkeExample() {
  DenseMatrix M(3, 3);
  M << 2, -1, 3, -1, 10, 2, -3, -2, 0;
  return Problem(M, Vector((Vector(3) << -1, -10, 6).finished()));
}

// Random J (rows x 6 bodies' worth of columns), A = J J^T + eps I.
inline DenseMatrix jacobianGram(Generator& g, int rows, int cols, double eps) {
  DenseMatrix J(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) J(i, j) = g.uniform(-1, 1);
  return J * J.transpose() + eps * DenseMatrix::Identity(rows, rows);
}

// Friction pyramids: per contact a normal row [0, inf) and two rows [-mu, mu] -> normal.
inline Problem frictionPyramids(DenseMatrix A, Generator& g, double mu) {
  const int n = static_cast<int>(A.rows());
  Vector b(n);
  for (int i = 0; i < n; ++i) b[i] = g.uniform(-1, 1);
  for (int k = 0; k < n; k += 3) b[k] = -g.uniform(0.2, 1);  // approaching contacts
  Problem p(std::move(A), b);
  p.findex.assign(n, -1);
  for (int k = 0; k < n; k += 3)
    for (int t = 1; t <= 2; ++t) {
      p.lo[k + t] = -mu;
      p.hi[k + t] = mu;
      p.findex[k + t] = k;
    }
  return p;
}

}  // namespace mlcp::test
