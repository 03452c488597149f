// The parts of the extension module mlcp._mlcp; the public Python API is python/mlcp/__init__.py,
// which checks and converts the arguments and wraps these functions' dicts in classes.
#pragma once

#include <nanobind/nanobind.h>

namespace mlcp::python {

// problem_from_file, problem_to_file, solve, solver_names (problems.cpp).
void bindProblems(nanobind::module_& m);
// run, engine_names (runs.cpp).
void bindRuns(nanobind::module_& m);
// sweep_plan, sweep_run, stability_cells, stability_cell and their CSV columns (studies.cpp).
void bindStudies(nanobind::module_& m);

}  // namespace mlcp::python
