// mlcp._mlcp: the core solvers, problem files and scene runs for Python (nanobind).
#include "bindings.hpp"

NB_MODULE(_mlcp, m) {
  m.doc() = "mlcp's C++ core (use the mlcp package, not this module)";
  mlcp::python::bindProblems(m);
  mlcp::python::bindRuns(m);
  mlcp::python::bindStudies(m);
}
