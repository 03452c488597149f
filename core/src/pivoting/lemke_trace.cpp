// traceLemke: the tableau-by-tableau print of Lemke's method (declared in mlcp/solvers/lemke.hpp).
#include <iomanip>
#include <ostream>
#include <sstream>

#include "mlcp/residual.hpp"
#include "mlcp/solvers/lemke.hpp"
#include "pivoting/lemke_tableau.hpp"

namespace mlcp {

namespace {

using detail::LemkeEnd;
using detail::LemkeOutcome;
using detail::LemkeTableau;
using detail::Rational;

std::string cell(const Rational& v) { return v.str(); }
std::string cell(double v) {
  std::ostringstream os;
  os << std::setprecision(6) << (std::abs(v) < 1e-13 ? 0.0 : v);  // no "-1.2e-17" noise
  return os.str();
}
double toDouble(const Rational& v) { return v.toDouble(); }
double toDouble(double v) { return v; }

// One line per basic variable: "z2 | -1/19 -2/19 0 ... | 21/19", columns right-aligned.
template <class T>
void printTableau(const LemkeTableau<T>& tab, std::ostream& out) {
  const int n = tab.size();
  std::vector<std::vector<std::string>> lines(n + 1);
  lines[0].push_back("basis");
  for (int v = 0; v <= tab.z0(); ++v) lines[0].push_back(tab.label(v));
  lines[0].push_back("q");
  for (int r = 0; r < n; ++r) {
    lines[r + 1].push_back(tab.label(tab.basic(r)));
    for (int c = 0; c <= tab.rhsColumn(); ++c) lines[r + 1].push_back(cell(tab.at(r, c)));
  }
  std::vector<size_t> width(lines[0].size(), 0);
  for (const auto& line : lines)
    for (size_t c = 0; c < line.size(); ++c) width[c] = std::max(width[c], line[c].size());
  for (const auto& line : lines) {
    out << std::left << std::setw(static_cast<int>(width[0])) << line[0] << " |" << std::right;
    for (size_t c = 1; c < line.size(); ++c) {
      if (c + 1 == line.size()) out << " |";
      out << ' ' << std::setw(static_cast<int>(width[c])) << line[c];
    }
    out << '\n';
  }
}

template <class T>
struct Printer {
  const LemkeTableau<T>& tab;
  std::ostream& out;
  bool stop() { return false; }
  void pivoted(int k, int entering, int leaving, int row) {
    out << "\npivot " << k << ": " << tab.label(entering) << " enters, " << tab.label(leaving)
        << " leaves (row " << row + 1 << ")\n";
    printTableau(tab, out);
  }
};

template <class T>
std::string vectorText(const std::vector<T>& v) {
  std::string s = "(";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + cell(v[i]);
  return s + ")";
}

// Runs and prints; fills z and the status/message of r.
template <class T, class Rules>
void traceWith(int n, const std::vector<T>& M, const std::vector<T>& q, const Rules& rules,
               int maxPivots, std::ostream& out, Vector& z, Result& r) {
  LemkeTableau<T> tab(n, M, q);
  out << "initial tableau [I, -M, -e | q]\n";
  printTableau(tab, out);
  Printer<T> printer{tab, out};
  const LemkeOutcome o = detail::runLemke(tab, rules, maxPivots, printer);
  r.iterations = o.pivots;
  std::vector<T> zs(n, T(0)), ws(n, T(0));
  for (int row = 0; row < n; ++row) {
    const int v = tab.basic(row);
    if (v < n) ws[v] = tab.rhs(row);
    if (v >= n && v < 2 * n) zs[v - n] = tab.rhs(row);
  }
  z.resize(n);
  for (int i = 0; i < n; ++i) z[i] = toDouble(zs[i]);
  out << '\n';
  switch (o.end) {
    case LemkeEnd::Solved:
      r.status = Status::Converged;
      r.message = o.pivots == 0 ? "q >= 0: z = 0, w = q solves the LCP without a pivot"
                                : "z0 left the basis: the table holds a solution";
      out << r.message << "\nz = " << vectorText(zs) << "\nw = " << vectorText(ws) << '\n';
      return;
    case LemkeEnd::Ray:
      r.status = Status::Failed;
      r.message = detail::rayMessage(o, tab.label(o.entering), "the LCP");
      break;
    case LemkeEnd::PivotLimit:
    case LemkeEnd::Stopped:
      r.status = Status::MaxIterations;
      r.message = "pivot limit " + std::to_string(maxPivots) + " reached";
      break;
  }
  out << r.message << '\n';
  z.setZero();  // no solution: report the start point, as the solver does
}

}  // namespace

Result traceLemke(const Problem& problem, std::ostream& out, const Options& options, Vector* x) {
  const double t0 = nowSeconds();
  Result r;
  if (std::string why = problem.validate(); !why.empty()) {
    r.status = Status::InvalidInput;
    r.message = why;
    return r;
  }
  if (problem.classify() != ProblemClass::StandardLcp) {
    r.status = Status::Unsupported;
    r.message = std::string(
                    "the Lemke trace shows standard LCPs only (lo = 0, hi = inf, no "
                    "findex); this problem is ") +
                toString(problem.classify());
    return r;
  }
  const int n = problem.size();
  const int maxPivots = options.maxPivots > 0 ? options.maxPivots : 50 * n + 100;
  const DenseMatrix A = problem.toDense();
  bool integral = true;
  for (int i = 0; i < n; ++i) {
    integral = integral && Rational::isSmallInteger(problem.b[i]);
    for (int j = 0; j < n; ++j) integral = integral && Rational::isSmallInteger(A(i, j));
  }
  Vector z;
  bool done = false;
  if (integral) {
    std::vector<Rational> M(static_cast<size_t>(n) * n), q(n);
    for (int i = 0; i < n; ++i) {
      q[i] = static_cast<std::int64_t>(problem.b[i]);
      for (int j = 0; j < n; ++j)
        M[static_cast<size_t>(i) * n + j] = static_cast<std::int64_t>(A(i, j));
    }
    std::ostringstream buffer;  // printed only if no fraction overflows
    try {
      traceWith(n, M, q, detail::ExactRules{}, maxPivots, buffer, z, r);
      out << "(exact fractions)\n" << buffer.str();
      done = true;
    } catch (const detail::RationalOverflow&) {
      out << "(the fractions overflowed 64 bits; the trace is printed in decimals)\n";
    }
  }
  if (!done) {
    std::vector<double> M(static_cast<size_t>(n) * n), q(n);
    for (int i = 0; i < n; ++i) {
      q[i] = problem.b[i];
      for (int j = 0; j < n; ++j) M[static_cast<size_t>(i) * n + j] = A(i, j);
    }
    detail::ToleranceRules rules;
    rules.pivotTolerance = options.pivotTolerance;
    traceWith(n, M, q, rules, maxPivots, out, z, r);
  }
  applyAccuracy(r, accuracy(problem, z), options.tolerance);
  if (x) *x = z;
  r.seconds = nowSeconds() - t0;
  return r;
}

}  // namespace mlcp
