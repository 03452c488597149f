// Solves a 2x2 LCP through the installed package; exit 0 only when it converges.
#include <cstdio>
#include <mlcp/registry.hpp>

int main() {
  mlcp::DenseMatrix A(2, 2);
  A << 2, 1, 1, 2;
  mlcp::Problem p(A, mlcp::Vector::Constant(2, -1.0));
  auto solver = mlcp::makeSolver("pgs");
  mlcp::Vector x;
  const mlcp::Result r = solver->solve(p, x);
  std::printf("%s residual %.2e x = (%g, %g)\n", mlcp::toString(r.status), r.residual, x[0], x[1]);
  return r.converged() ? 0 : 1;
}
