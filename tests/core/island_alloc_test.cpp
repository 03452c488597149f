// Heap allocations of an island's solve in steady state (the same island solved again, as an
// engine does every step), counted by replacing malloc in this test's own executable: bounded
// by a small constant that does not grow with the island (what is left is the result's message
// strings; every workspace, buffer and factor is reused).
#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "common/cube_on_ground.hpp"
#include "common/redundant_joint.hpp"
#include "mlcp/island/row_solver.hpp"
#include "mlcp/registry.hpp"

extern "C" void* __libc_malloc(std::size_t);
namespace {
long g_allocations = 0;
}  // namespace
// Every allocation of this executable (operator new included) comes through here.
extern "C" void* malloc(std::size_t n) {
  ++g_allocations;
  return __libc_malloc(n);
}

namespace mlcp {
namespace {

// A cube on the ground with `contacts` contacts (three rows each, friction), cfm 1e-5.
RowSystem box(int contacts) {
  std::vector<Eigen::Vector3d> points;
  for (int c = 0; c < contacts; ++c) {
    const double a = 6.283185307179586 * c / contacts;
    points.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), -0.5);
  }
  const Vector6 v = (Vector6() << 0.1, 0, -0.2, 0, 0.05, 0).finished();
  return test::cubeOnGround(points, v, 0.5, 1e-5);
}

// Allocations per solve of `rows` by `solver` after 20 solves of it (the steady state).
double allocationsPerSolve(const std::string& solver, const RowSystem& rows) {
  RowSolverSettings settings;
  settings.solver = solver;
  RowSolver island(settings);
  Vector x;
  const Vector start = Vector::Zero(rows.size());
  for (int i = 0; i < 20; ++i) island.solve(rows, start, x, 1);
  const long before = g_allocations;
  for (int i = 0; i < 100; ++i) {
    const IslandSolve s = island.solve(rows, start, x, 1);
    EXPECT_TRUE(s.accepted) << s.result.message;
  }
  return (g_allocations - before) / 100.0;
}

TEST(IslandAllocations, SteadyStateSolvesAllocateOnlyTheirMessagesWhateverTheSize) {
  RowSystem joint = test::redundantBallJoint(0);  // its first copy: one ball joint, 3 rows
  joint.rows.resize(3);
  for (Vector* v : {&joint.b, &joint.lo, &joint.hi, &joint.cfm}) v->conservativeResize(3);
  for (const char* solver : {"auto", "dantzig", "pgs"}) {
    SCOPED_TRACE(solver);
    const double small = allocationsPerSolve(solver, box(4));
    const double large = allocationsPerSolve(solver, box(16));
    EXPECT_LE(small, 2);
    EXPECT_LE(large, small);
  }
  EXPECT_LE(allocationsPerSolve("ldlt", joint), 1);
}

// A dense LCP of n rows, A = I + 0.1 (ones), b alternating in sign (about half the rows active).
Problem denseLcp(int n) {
  DenseMatrix A = DenseMatrix::Identity(n, n) + 0.1 * DenseMatrix::Ones(n, n);
  Vector b(n);
  for (int i = 0; i < n; ++i) b[i] = i % 2 ? 0.5 : -1.0;
  return Problem(A, b);
}

// Allocations per Solver::solve of `p` by `solver` after 20 solves of it.
double allocationsPerApiSolve(const std::string& solver, const Problem& p) {
  std::unique_ptr<Solver> s = makeSolver(solver);
  Vector x;
  for (int i = 0; i < 20; ++i) s->solve(p, x);
  const long before = g_allocations;
  for (int i = 0; i < 100; ++i) {
    const Result r = s->solve(p, x);
    EXPECT_EQ(r.status, Status::Converged) << r.message;
  }
  return (g_allocations - before) / 100.0;
}

// The core API on tiny problems (auto's chain of solvers included): the workspaces of every
// layer are kept, the problem is validated once, and no message stream is made on success.
TEST(IslandAllocations, RepeatApiSolvesOfATinyLcpAllocateOnlyTheirMessages) {
  for (const char* solver : {"auto", "dantzig"}) {
    SCOPED_TRACE(solver);
    const double small = allocationsPerApiSolve(solver, denseLcp(5));
    const double large = allocationsPerApiSolve(solver, denseLcp(20));
    EXPECT_LE(small, 2);
    EXPECT_LE(large, small);
  }
}

}  // namespace
}  // namespace mlcp
