// mlcp._mlcp.Problem (an mlcp::Problem whose vectors numpy reads in place), its files, and
// solve by registry name. Errors the CLI reports as invalid input (Problem::validate()'s
// message, a file's FormatError, an unknown solver name, a bad guess) raise ValueError with the
// same message; numerical outcomes, converged or not, are a status in the returned dict. The
// solver settings are `mlcp solve`'s, checked by the same code (tools/mlcp/solver_settings.hpp).
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "arrays.hpp"
#include "bindings.hpp"
#include "mlcp/io.hpp"
#include "mlcp/registry.hpp"
#include "mlcp/solver_settings.hpp"

namespace mlcp::python {

namespace {

using OptVector = std::optional<InVector>;
using OptIndex = std::optional<InIndex>;

// Bounds and findex given (or not) by the caller; then the whole problem is validated.
Problem finish(Problem p, const OptVector& lo, const OptVector& hi, const OptIndex& findex) {
  if (lo) p.lo = view(*lo);
  if (hi) p.hi = view(*hi);
  if (findex) p.findex.assign(findex->data(), findex->data() + findex->shape(0));
  const std::string error = p.validate();
  if (!error.empty()) throw nb::value_error(error.c_str());
  return p;
}

Problem dense(const InMatrix& A, const InVector& b, const OptVector& lo, const OptVector& hi,
              const OptIndex& findex) {
  Eigen::Map<const DenseMatrix> a(A.data(), static_cast<Eigen::Index>(A.shape(0)),
                                  static_cast<Eigen::Index>(A.shape(1)));
  return finish(Problem(DenseMatrix(a), Vector(view(b))), lo, hi, findex);
}

// A from CSR arrays (sorted column indices without duplicates, as scipy's canonical format).
Problem sparse(int rows, int cols, const InIndex& indptr, const InIndex& indices,
               const InVector& data, const InVector& b, const OptVector& lo, const OptVector& hi,
               const OptIndex& findex) {
  if (rows < 0 || cols < 0 || indptr.shape(0) != static_cast<std::size_t>(rows) + 1 ||
      indices.shape(0) != data.shape(0) || indptr.data()[rows] != static_cast<int>(data.shape(0)))
    throw nb::value_error("A: inconsistent CSR arrays (indptr, indices, data)");
  for (int i = 0; i < rows; ++i) {
    const int begin = indptr.data()[i], end = indptr.data()[i + 1];
    if (begin > end || begin < 0) throw nb::value_error("A: CSR indptr is not non-decreasing");
    for (int k = begin; k < end; ++k) {
      const int j = indices.data()[k];
      if (j < 0 || j >= cols || (k > begin && j <= indices.data()[k - 1]))
        throw nb::value_error("A: CSR column indices out of range or not sorted");
    }
  }
  Eigen::Map<const SparseMatrix> a(rows, cols, static_cast<Eigen::Index>(data.shape(0)),
                                   indptr.data(), indices.data(), data.data());
  return finish(Problem(SparseMatrix(a), Vector(view(b))), lo, hi, findex);
}

Problem load(const std::string& path) {
  try {
    return io::readProblem(path);
  } catch (const io::FormatError& e) {
    throw nb::value_error(e.what());
  }
}

void save(const Problem& p, const std::string& path) {
  try {
    io::writeProblemJson(p, path);
  } catch (const io::FormatError& e) {
    throw nb::value_error(e.what());
  }
}

// A vector member of the problem as a writable numpy view kept alive by the problem.
Array1<double> member(Vector& v) {
  return Array1<double>(v.data(), {static_cast<std::size_t>(v.size())}, nb::handle());
}

nb::tuple csr(Problem& p) {
  // The problem's own CSR storage (compressed whenever A is set), viewed in place.
  SparseMatrix& a = const_cast<SparseMatrix&>(p.sparseA());
  const auto nnz = static_cast<std::size_t>(a.nonZeros());
  const auto rows = static_cast<std::size_t>(a.rows());
  nb::object self = nb::find(p);
  return nb::make_tuple(Array1<int>(a.outerIndexPtr(), {rows + 1}, self),
                        Array1<int>(a.innerIndexPtr(), {nnz}, self),
                        Array1<double>(a.valuePtr(), {nnz}, self));
}

// (solver, parameter, value, value as written): a typed parameter, e.g. ("newton",
// "pivoting_steps", 0.0, "0").
using ParamTuple = std::tuple<std::string, std::string, double, std::string>;

// options[name] as a T; TypeError naming it otherwise.
template <typename T>
T option(const nb::dict& options, const char* name, const char* expected) {
  try {
    return nb::cast<T>(options[name]);
  } catch (const nb::cast_error&) {
    throw nb::type_error((std::string(name) + " must be " + expected).c_str());
  }
}

// The settings of `mlcp solve`, checked by the same code (solver_settings.hpp); a bad one raises
// ValueError with its message, "newton: " before a typed parameter's.
cli::SolverSettings solveSettings(const nb::dict& options, const std::vector<ParamTuple>& params) {
  cli::SolverSettings s;
  s.tolerance = option<double>(options, "tol", "a number");
  s.maxIterations = option<int>(options, "max_iter", "an int");
  s.relaxation = option<double>(options, "relaxation", "a number");
  s.timeBudget = option<double>(options, "time_budget", "a number");
  s.maxPivots = option<int>(options, "max_pivots", "an int");
  s.checkEvery = option<int>(options, "check_every", "an int");
  s.pivotTolerance = option<double>(options, "pivot_tolerance", "a number");
  s.frictionBounds = option<std::string>(options, "friction_bounds", "a str");
  try {
    cli::checkSettings(s);
  } catch (const std::invalid_argument& e) {
    throw nb::value_error(e.what());
  }
  for (const auto& [solver, key, value, text] : params) {
    try {
      cli::setSolverParam(s, solver, key, value, text, false);
    } catch (const std::invalid_argument& e) {
      throw nb::value_error((solver + ": " + e.what()).c_str());
    }
  }
  return s;
}

nb::dict solve(const Problem& p, const std::string& name, const nb::dict& options,
               const std::vector<ParamTuple>& params, const OptVector& guess) {
  const cli::SolverSettings settings = solveSettings(options, params);
  std::string error;
  std::unique_ptr<Solver> solver = makeSolver(name, &error);
  if (!solver) throw nb::value_error(error.c_str());
  cli::applySettings(settings, *solver);
  Vector x;
  Result r;
  {
    Vector start = guess ? Vector(view(*guess)) : Vector();
    nb::gil_scoped_release unlocked;
    r = guess ? solver->solveWithGuess(p, start, x) : solver->solve(p, x);
  }
  if (r.status == Status::InvalidInput) throw nb::value_error(r.message.c_str());
  Vector w = x.size() == p.size() ? p.slack(x) : Vector();
  nb::dict out;
  out["x"] = toNumpy(std::move(x));
  out["w"] = toNumpy(std::move(w));
  out["status"] = toString(r.status);
  out["residual"] = r.residual;
  out["iterations"] = r.iterations;
  out["solver"] = r.solver.empty() ? std::string(solver->name()) : r.solver;
  out["message"] = r.message;
  out["complementarity"] = r.complementarity;
  out["bound_violation"] = r.boundViolation;
  out["seconds"] = r.seconds;
  out["fallbacks"] = r.fallbacks;
  return out;
}

// Every typed parameter: (solver, name, kind "int" / "float" / "bool", default, accepted values,
// what it is).
using ParamInfo =
    std::tuple<std::string, std::string, std::string, double, std::string, std::string>;

std::vector<ParamInfo> solverParams() {
  std::vector<ParamInfo> out;
  for (const cli::SolverParam& p : cli::solverParams()) {
    const std::unique_ptr<Solver> fresh = makeSolver(p.solver);
    const bool flag = p.whole && p.lo == 0 && p.hi == 1;
    out.emplace_back(p.solver, p.name, flag ? "bool" : (p.whole ? "int" : "float"), p.get(*fresh),
                     p.range, p.help);
  }
  return out;
}

std::vector<std::string> solverNames() {
  std::vector<std::string> names;
  for (const SolverInfo& s : solvers()) names.emplace_back(s.name);
  return names;
}

}  // namespace

void bindProblems(nb::module_& m) {
  nb::class_<Problem>(m, "Problem")
      .def_static("dense", &dense, nb::arg("A"), nb::arg("b"), nb::arg("lo").none(),
                  nb::arg("hi").none(), nb::arg("findex").none())
      .def_static("sparse", &sparse, nb::arg("rows"), nb::arg("cols"), nb::arg("indptr"),
                  nb::arg("indices"), nb::arg("data"), nb::arg("b"), nb::arg("lo").none(),
                  nb::arg("hi").none(), nb::arg("findex").none())
      .def_static("load", &load, nb::arg("path"))
      .def("save", &save, nb::arg("path"))
      .def("to_json", &io::problemToJson)
      .def_prop_ro("n", &Problem::size)
      .def_prop_ro("is_sparse", &Problem::isSparse)
      .def_prop_ro("kind", [](const Problem& p) { return std::string(toString(p.classify())); })
      .def_prop_ro(
          "b", [](Problem& p) { return member(p.b); }, nb::rv_policy::reference_internal)
      .def_prop_ro(
          "lo", [](Problem& p) { return member(p.lo); }, nb::rv_policy::reference_internal)
      .def_prop_ro(
          "hi", [](Problem& p) { return member(p.hi); }, nb::rv_policy::reference_internal)
      .def_prop_ro("findex", [](const Problem& p) { return p.findex; })
      .def_prop_ro(
          "dense_A",
          [](Problem& p) {
            auto& a = const_cast<DenseMatrix&>(p.denseA());
            const std::size_t shape[2] = {static_cast<std::size_t>(a.rows()),
                                          static_cast<std::size_t>(a.cols())};
            return Array2(a.data(), 2, shape, nb::handle());
          },
          nb::rv_policy::reference_internal)
      .def_prop_ro("csr", &csr)
      .def("solve", &solve, nb::arg("solver"), nb::arg("options"), nb::arg("params"),
           nb::arg("guess").none());
  m.def("solver_names", &solverNames);
  m.def("solver_params", &solverParams);
}

}  // namespace mlcp::python
