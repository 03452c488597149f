#include "mlcp/io.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "mlcp/input_limits.hpp"

namespace mlcp::io {

using nlohmann::json;

namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw FormatError(source + ": " + what);
}

std::string slurp(const std::string& path) {
  return readInputFile(path, kMaxProblemFileBytes, "problem file");
}

json parseDocument(const std::string& text, const std::string& source) {
  checkJsonNesting(text, source);
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    fail(source, jsonErrorText(e));
  }
}

// Entries of A and b, and finite bounds, are at most this large in magnitude: products of two
// of them and sums of a million such products stay finite (1e100^2 * 1e6 < 1e308).
constexpr double kMaxMagnitude = 1e100;

double checkedEntry(double v, const std::string& source, const std::string& where) {
  if (!(std::abs(v) <= kMaxMagnitude)) {
    std::ostringstream os;
    os << where << " = " << std::setprecision(3) << v << " is outside [-1e100, 1e100]";
    fail(source, os.str());
  }
  return v;
}

double number(const json& v, const std::string& source, const std::string& where) {
  if (v.is_number()) return checkedEntry(v.get<double>(), source, where);
  if (v.is_string()) {
    const std::string s = v.get<std::string>();
    if (s == "inf" || s == "+inf") return kInf;
    if (s == "-inf") return -kInf;
  }
  fail(source, where + " must be a number or \"inf\"/\"-inf\", got " + capped(v.dump()));
}

Vector vectorField(const json& doc, const char* key, int n, const std::string& source,
                   double fallback, bool required) {
  if (!doc.contains(key)) {
    if (required) fail(source, std::string("missing \"") + key + "\"");
    return Vector::Constant(n, fallback);
  }
  const json& a = doc[key];
  if (!a.is_array()) fail(source, std::string("\"") + key + "\" must be an array");
  if (static_cast<int>(a.size()) != n) {
    fail(source, std::string("\"") + key + "\" has " + std::to_string(a.size()) +
                     " entries, expected n = " + std::to_string(n));
  }
  Vector v(n);
  for (int i = 0; i < n; ++i)
    v[i] = number(a[i], source, std::string(key) + "[" + std::to_string(i) + "]");
  return v;
}

void setMatrix(Problem& p, const json& a, int n, const std::string& source) {
  if (a.is_array()) {
    if (static_cast<int>(a.size()) != n)
      fail(source,
           "\"A\" has " + std::to_string(a.size()) + " rows, expected n = " + std::to_string(n));
    DenseMatrix A(n, n);
    for (int i = 0; i < n; ++i) {
      const json& row = a[i];
      if (!row.is_array() || static_cast<int>(row.size()) != n)
        fail(source, "\"A\" row " + std::to_string(i) +
                         " must be an array of n = " + std::to_string(n) + " numbers");
      for (int j = 0; j < n; ++j) {
        if (!row[j].is_number())
          fail(source, "A[" + std::to_string(i) + "][" + std::to_string(j) + "] is not a number");
        A(i, j) = checkedEntry(row[j].get<double>(), source,
                               "A[" + std::to_string(i) + "][" + std::to_string(j) + "]");
      }
    }
    p.setA(std::move(A));
    return;
  }
  if (!a.is_object()) fail(source, "\"A\" must be an array of rows or {rows, cols, triplets}");
  if (!a.contains("rows") || !a.contains("cols") || !a.contains("triplets"))
    fail(source, "sparse \"A\" needs \"rows\", \"cols\" and \"triplets\"");
  if (!a["rows"].is_number_integer() || !a["cols"].is_number_integer() ||
      a["rows"].get<long long>() != n || a["cols"].get<long long>() != n)
    fail(source, "sparse \"A\" must be n x n with n = " + std::to_string(n));
  const json& t = a["triplets"];
  if (!t.is_array()) fail(source, "\"A.triplets\" must be an array of [i, j, v]");
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    const json& e = t[k];
    const std::string where = "A.triplets[" + std::to_string(k) + "]";
    if (!e.is_array() || e.size() != 3 || !e[0].is_number_integer() || !e[1].is_number_integer() ||
        !e[2].is_number())
      fail(source, where + " must be [i, j, v] with integer i, j");
    const long long i = e[0].get<long long>(), j = e[1].get<long long>();
    if (i < 0 || i >= n || j < 0 || j >= n)
      fail(source, where + " index (" + std::to_string(i) + ", " + std::to_string(j) +
                       ") is outside 0.." + std::to_string(n - 1));
    triplets.emplace_back(static_cast<int>(i), static_cast<int>(j),
                          checkedEntry(e[2].get<double>(), source, where));
  }
  SparseMatrix A(n, n);
  A.setFromTriplets(triplets.begin(), triplets.end());  // sums duplicates
  p.setA(std::move(A));
}

json numberOrInf(double v) {
  if (v == kInf) return "inf";
  if (v == -kInf) return "-inf";
  return v;
}

void checkValid(const Problem& p, const std::string& source) {
  if (std::string why = p.validate(); !why.empty()) fail(source, why);
}

}  // namespace

Problem parseProblemJson(const std::string& text, const std::string& source) {
  const json doc = parseDocument(text, source);
  if (!doc.is_object()) fail(source, "top level must be a JSON object");
  if (!doc.contains("format") || doc["format"] != "mlcp-problem/1")
    fail(source, "\"format\" must be \"mlcp-problem/1\"");
  if (!doc.contains("n") || !doc["n"].is_number_integer() || doc["n"].get<long long>() < 0 ||
      doc["n"].get<long long>() > 100000000)
    fail(source, "\"n\" must be a non-negative integer");
  const int n = static_cast<int>(doc["n"].get<long long>());
  if (!doc.contains("A")) fail(source, "missing \"A\"");
  Problem p;
  // b first: its n entries bound n by the file's size before A (n x n, or n + 1 column
  // pointers) is allocated.
  p.b = vectorField(doc, "b", n, source, 0, true);
  setMatrix(p, doc["A"], n, source);
  p.lo = vectorField(doc, "lo", n, source, 0, false);
  p.hi = vectorField(doc, "hi", n, source, kInf, false);
  if (doc.contains("findex")) {
    const json& f = doc["findex"];
    if (!f.is_array() || static_cast<int>(f.size()) != n)
      fail(source, "\"findex\" must be an array of n = " + std::to_string(n) + " integers");
    p.findex.resize(n);
    for (int i = 0; i < n; ++i) {
      if (!f[i].is_number_integer())
        fail(source, "findex[" + std::to_string(i) + "] is not an integer");
      const long long v = f[i].get<long long>();
      p.findex[i] = (v < -1 || v >= n) ? -2 : static_cast<int>(v);
      if (p.findex[i] == -2)
        fail(source, "findex[" + std::to_string(i) + "] = " + std::to_string(v) +
                         " is out of range [-1, " + std::to_string(n - 1) + "]");
    }
  }
  checkValid(p, source);
  return p;
}

Problem readProblemJson(const std::string& path) { return parseProblemJson(slurp(path), path); }

std::string problemToJson(const Problem& p) {
  json doc;
  doc["format"] = "mlcp-problem/1";
  doc["n"] = p.size();
  if (p.isSparse()) {
    json t = json::array();
    const SparseMatrix& A = p.sparseA();
    for (int i = 0; i < A.outerSize(); ++i)
      for (SparseMatrix::InnerIterator it(A, i); it; ++it)
        t.push_back({it.row(), it.col(), it.value()});
    doc["A"] = {{"rows", p.size()}, {"cols", p.size()}, {"triplets", t}};
  } else {
    json rows = json::array();
    for (int i = 0; i < p.size(); ++i) {
      json row = json::array();
      for (int j = 0; j < p.size(); ++j) row.push_back(p.denseA()(i, j));
      rows.push_back(row);
    }
    doc["A"] = rows;
  }
  json b = json::array(), lo = json::array(), hi = json::array();
  for (int i = 0; i < p.size(); ++i) {
    b.push_back(p.b[i]);
    lo.push_back(numberOrInf(p.lo[i]));
    hi.push_back(numberOrInf(p.hi[i]));
  }
  doc["b"] = b;
  doc["lo"] = lo;
  doc["hi"] = hi;
  if (p.hasFindex()) doc["findex"] = p.findex;
  // max_digits10 is what nlohmann uses for doubles, so the file round-trips exactly.
  return doc.dump(1) + "\n";
}

void writeProblemJson(const Problem& p, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw FormatError(path + ": cannot open file for writing");
  out << problemToJson(p);
  if (!out) throw FormatError(path + ": write failed");
}

namespace {

// Whitespace-separated tokens of a Siconos .dat file, with the file name in every error.
class Tokens {
 public:
  Tokens(const std::string& text, std::string source)
      : in_(text), source_(std::move(source)), maxCount_((text.size() + 1) / 2) {}

  // The most numbers the text can still hold (each takes a character and a separator): a
  // bound on every count read, checked before anything of that size is allocated.
  long long maxCount() const { return maxCount_; }

  long long integer(const char* what) {
    std::string tok = next(what);
    std::size_t used = 0;
    long long v = 0;
    try {
      v = std::stoll(tok, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != tok.size())
      fail(source_, std::string("expected an integer for ") + what + ", got '" + capped(tok) + "'");
    return v;
  }

  double real(const char* what) {
    std::string tok = next(what);
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(tok, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != tok.size() || !std::isfinite(v))
      fail(source_,
           std::string("expected a finite number for ") + what + ", got '" + capped(tok) + "'");
    return checkedEntry(v, source_, what);
  }

  const std::string& source() const { return source_; }

 private:
  std::string next(const char* what) {
    std::string tok;
    if (!(in_ >> tok)) fail(source_, std::string("file ends before ") + what);
    return tok;
  }
  std::istringstream in_;
  std::string source_;
  long long maxCount_;
};

long long checkedSize(Tokens& t, const char* what, long long maxValue) {
  const long long v = t.integer(what);
  if (v < 0 || v > maxValue)
    fail(t.source(), std::string(what) + " = " + std::to_string(v) + " is out of range");
  return v;
}

// Siconos writes its column-major storage in sequence (NM_write_in_file), so each printed
// line is a column; the block files agree only when read this way.
DenseMatrix readColumnMajor(Tokens& t, int rows, int cols, const char* what) {
  if (static_cast<long long>(rows) * cols > t.maxCount())
    fail(t.source(), "a " + std::to_string(rows) + "x" + std::to_string(cols) +
                         " matrix needs more entries than the file holds");
  DenseMatrix M(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) M(i, j) = t.real(what);
  return M;
}

DenseMatrix readSiconosDense(Tokens& t, int n) {
  const long long rows = t.integer("matrix rows"), cols = t.integer("matrix cols");
  const long long rows2 = t.integer("matrix rows"), cols2 = t.integer("matrix cols");
  if (rows != n || cols != n || rows2 != n || cols2 != n)
    fail(t.source(), "dense matrix is " + std::to_string(rows) + "x" + std::to_string(cols) +
                         ", expected " + std::to_string(n) + "x" + std::to_string(n));
  return readColumnMajor(t, n, n, "a matrix entry");
}

// Siconos' SparseBlockStructuredMatrix text form: size0 size1 nbblocks blocknumber0
// blocknumber1, cumulative block sizes of rows and columns, filled1 filled2, the block-row
// pointer (index1) and block-column indices (index2), then per block its number and its
// values column by column.
SparseMatrix readSiconosBlock(Tokens& t, int n) {
  const long long size0 = t.integer("matrix rows"), size1 = t.integer("matrix cols");
  if (size0 != n || size1 != n) fail(t.source(), "block matrix size does not match n");
  const long long nbBlocks = checkedSize(t, "number of blocks", t.maxCount());
  const long long nRowBlocks = checkedSize(t, "number of block rows", n);
  const long long nColBlocks = checkedSize(t, "number of block columns", n);
  std::vector<long long> rowEnd(nRowBlocks), colEnd(nColBlocks);
  for (auto& e : rowEnd) e = checkedSize(t, "a block row size", n);
  for (auto& e : colEnd) e = checkedSize(t, "a block column size", n);
  auto checkCumulative = [&](const std::vector<long long>& ends, const char* what) {
    for (std::size_t k = 0; k < ends.size(); ++k)
      if ((k > 0 && ends[k] <= ends[k - 1]) || (k == 0 && ends[k] <= 0))
        fail(t.source(), std::string(what) + " sizes are not increasing");
    if (ends.empty() || ends.back() != n)
      fail(t.source(), std::string(what) + " sizes do not add up to n");
  };
  checkCumulative(rowEnd, "block row");
  checkCumulative(colEnd, "block column");
  const long long filled1 = t.integer("filled1"), filled2 = t.integer("filled2");
  if (filled1 != nRowBlocks + 1 || filled2 != nbBlocks)
    fail(t.source(), "block index sizes do not match the block counts");
  std::vector<long long> rowPtr(filled1), colIndex(filled2);
  for (auto& e : rowPtr) e = checkedSize(t, "a block row pointer", nbBlocks);
  for (auto& e : colIndex) e = checkedSize(t, "a block column index", nColBlocks - 1);
  if (rowPtr.front() != 0 || rowPtr.back() != nbBlocks)
    fail(t.source(), "block row pointers do not span the blocks");
  std::vector<Eigen::Triplet<double>> triplets;
  for (long long bi = 0; bi < nRowBlocks; ++bi) {
    if (rowPtr[bi + 1] < rowPtr[bi]) fail(t.source(), "block row pointers decrease");
    const long long r0 = bi ? rowEnd[bi - 1] : 0, nr = rowEnd[bi] - r0;
    for (long long k = rowPtr[bi]; k < rowPtr[bi + 1]; ++k) {
      t.integer("a block number");
      const long long bj = colIndex[k];
      const long long c0 = bj ? colEnd[bj - 1] : 0, nc = colEnd[bj] - c0;
      for (long long c = 0; c < nc; ++c)
        for (long long r = 0; r < nr; ++r)
          triplets.emplace_back(static_cast<int>(r0 + r), static_cast<int>(c0 + c),
                                t.real("a block entry"));
    }
  }
  SparseMatrix M(n, n);
  M.setFromTriplets(triplets.begin(), triplets.end());
  return M;
}

}  // namespace

Problem readSiconosLcp(const std::string& path) { return parseSiconosLcp(slurp(path), path); }

Problem parseSiconosLcp(const std::string& text, const std::string& path) {
  Tokens t(text, path);
  const int n = static_cast<int>(checkedSize(t, "n", std::min(10000000LL, t.maxCount())));
  const long long storage = t.integer("storage type");
  Problem p;
  if (storage == 0) {
    p.setA(readSiconosDense(t, n));
  } else if (storage == 1) {
    p.setA(readSiconosBlock(t, n));
  } else {
    fail(path, "storage type " + std::to_string(storage) + " is not 0 (dense) or 1 (sparse block)");
  }
  p.b.resize(n);
  for (int i = 0; i < n; ++i) p.b[i] = t.real("an entry of q");
  p.lo = Vector::Zero(n);
  p.hi = Vector::Constant(n, kInf);
  checkValid(p, path);
  return p;
}

namespace {

// Storage 1's row blocks: starts 0 = r_0 < r_1 < ... < r_K = size, then one flag per block
// (0: equality rows, 1: complementarity rows). Rows of an equality block are free in our form.
void readMlcpBlocks(Tokens& t, long long size, Problem& p) {
  std::vector<long long> starts{t.integer("the first block row")};
  if (starts[0] != 0) fail(t.source(), "the first block row is not 0");
  while (starts.back() < size) {
    starts.push_back(t.integer("a block row"));
    if (starts.back() <= starts[starts.size() - 2])
      fail(t.source(), "block rows are not increasing");
  }
  if (starts.back() != size) fail(t.source(), "block rows do not end at n + m");
  p.lo.resize(size);
  for (std::size_t k = 0; k + 1 < starts.size(); ++k) {
    const long long flag = t.integer("a block's complementarity flag");
    if (flag != 0 && flag != 1) fail(t.source(), "a block's complementarity flag is not 0 or 1");
    p.lo.segment(starts[k], starts[k + 1] - starts[k]).setConstant(flag ? 0.0 : -kInf);
  }
}

// Storage 1's M = [[A, C], [D, B]] (a NumericsMatrix: dense or sparse block) and q = [a; b].
void readMlcpStorage1(Tokens& t, long long size, Problem& p) {
  const long long storage = t.integer("M's storage type");
  if (storage == 0) {
    // size0 size1, then the dense block's own "rows cols".
    const long long rows = t.integer("M's rows"), cols = t.integer("M's columns");
    if (t.integer("M's rows") != rows || t.integer("M's columns") != cols)
      fail(t.source(), "M's two size lines differ");
    if (rows != cols)
      throw UnsupportedProblem(t.source() + ": M is " + std::to_string(rows) + " x " +
                               std::to_string(cols) +
                               ": a rectangular MLCP has no square canonical form");
    if (rows != size) fail(t.source(), "M's size does not match n + m");
    p.setA(readColumnMajor(t, static_cast<int>(size), static_cast<int>(size), "an entry of M"));
  } else if (storage == 1) {
    p.setA(readSiconosBlock(t, static_cast<int>(size)));
  } else {
    fail(t.source(), "M's storage type is not 0 (dense) or 1 (sparse block)");
  }
  p.b.resize(size);
  for (long long i = 0; i < size; ++i) p.b[i] = t.real("an entry of q");
}

// Storage 2's blocks A (n x n), B (m x m), C (n x m), D (m x n), each row by row (Siconos
// prints and reads them with the row index outermost), then a (n) and b (m), assembled into
// M = [[A, C], [D, B]] and q = [a; b].
DenseMatrix readRowMajor(Tokens& t, int rows, int cols, const char* what) {
  if (static_cast<long long>(rows) * cols > t.maxCount())
    fail(t.source(), "a " + std::to_string(rows) + "x" + std::to_string(cols) +
                         " matrix needs more entries than the file holds");
  DenseMatrix M(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) M(i, j) = t.real(what);
  return M;
}

std::pair<DenseMatrix, Vector> readMlcpStorage2(Tokens& t, int n, int m) {
  DenseMatrix M(n + m, n + m);
  M.topLeftCorner(n, n) = readRowMajor(t, n, n, "an entry of A");
  M.bottomRightCorner(m, m) = readRowMajor(t, m, m, "an entry of B");
  M.topRightCorner(n, m) = readRowMajor(t, n, m, "an entry of C");
  M.bottomLeftCorner(m, n) = readRowMajor(t, m, n, "an entry of D");
  Vector q(n + m);
  for (int i = 0; i < n + m; ++i) q[i] = t.real(i < n ? "an entry of a" : "an entry of b");
  return {std::move(M), std::move(q)};
}

// Both storages in one file must describe one problem (to rounding in the printed digits).
void checkStoragesAgree(const Problem& p, const DenseMatrix& M, const Vector& q, int n,
                        const std::string& source) {
  const DenseMatrix A = p.toDense();
  const double scale = 1 + std::max(A.cwiseAbs().maxCoeff(), p.b.cwiseAbs().maxCoeff());
  if ((A - M).cwiseAbs().maxCoeff() > 1e-12 * scale ||
      (p.b - q).cwiseAbs().maxCoeff() > 1e-12 * scale)
    fail(source, "storage 1 (M, q) and storage 2 (A, B, C, D, a, b) describe different problems");
  for (int i = 0; i < p.size(); ++i)
    if ((p.lo[i] == 0) != (i >= n))
      fail(source, "storage 1's blocks do not put the n equalities before the m complementarities");
}

}  // namespace

Problem readSiconosMlcp(const std::string& path) {
  Tokens t(slurp(path), path);
  const long long storage1 = t.integer("storage 1 flag"), storage2 = t.integer("storage 2 flag");
  if ((storage1 != 0 && storage1 != 1) || (storage2 != 0 && storage2 != 1) ||
      storage1 + storage2 == 0)
    fail(path, "the storage flags are not 0/1 with at least one set");
  const long long limit = std::min(10000000LL, t.maxCount());
  const int n = static_cast<int>(checkedSize(t, "n", limit));
  const int m = static_cast<int>(checkedSize(t, "m", limit - n));
  Problem p;
  if (storage1) {
    readMlcpBlocks(t, n + m, p);
    readMlcpStorage1(t, n + m, p);
  }
  if (storage2) {
    auto [M, q] = readMlcpStorage2(t, n, m);
    if (storage1) {
      checkStoragesAgree(p, M, q, n, path);
    } else {
      p.setA(std::move(M));
      p.b = std::move(q);
      p.lo = Vector::Constant(n + m, 0.0);
      p.lo.head(n).setConstant(-kInf);
    }
  }
  p.hi = Vector::Constant(n + m, kInf);
  checkValid(p, path);
  return p;
}

bool isSiconosMlcpName(const std::string& path) {
  const std::string suffix = "mlcp.dat";
  return path.size() >= suffix.size() &&
         path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0;
}

Problem readProblem(const std::string& path) {
  auto endsWith = [&](const char* suffix) {
    const std::string s(suffix);
    return path.size() >= s.size() && path.compare(path.size() - s.size(), s.size(), s) == 0;
  };
  if (isSiconosMlcpName(path)) return readSiconosMlcp(path);
  if (endsWith(".dat")) return readSiconosLcp(path);
  return readProblemJson(path);
}

Vector readVectorJson(const std::string& path) {
  json doc = parseDocument(slurp(path), path);
  if (doc.is_object() && doc.contains("x")) doc = doc["x"];
  if (!doc.is_array()) fail(path, "expected an array of numbers (or an object with \"x\")");
  Vector v(doc.size());
  for (std::size_t i = 0; i < doc.size(); ++i) {
    if (!doc[i].is_number()) fail(path, "entry " + std::to_string(i) + " is not a number");
    v[i] = doc[i].get<double>();
  }
  return v;
}

}  // namespace mlcp::io
