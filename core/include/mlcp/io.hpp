// mlcp/io.hpp: problem files.
//
// mlcp-problem/1 (JSON), read and written:
//
//   {"format": "mlcp-problem/1", "n": 3,
//    "A": [[2, -1, 3], [-1, 10, 2], [-3, -2, 0]],      (dense, row by row), or
//    "A": {"rows": 3, "cols": 3, "triplets": [[i, j, v], ...]},   (sparse; duplicates summed)
//    "b": [-1, -10, 6],
//    "lo": [0, "-inf", -1],    optional, default 0; numbers or the strings "inf" / "-inf"
//    "hi": ["inf", "inf", 1],  optional, default "inf"
//    "findex": [-1, -1, 0]}    optional, default all -1
//
// Siconos LCP .dat files (find z >= 0, w = M z + q >= 0, z'w = 0; their convention is ours):
// dense (storage 0) and sparse-block (storage 1) matrices, see tests/data/siconos/README.md.
// Both store their values column by column (the dense form prints one column per line).
//
// Siconos MLCP .dat files (`*mlcp.dat`; Siconos' mixedLinearComplementarity_newFromFile):
// unknowns u (n, free) and v (m, complementary) with
//     0 = A u + C v + a,    w = D u + B v + b >= 0,  v >= 0,  v'w = 0,
// which is our form with z = [u; v], M = [[A, C], [D, B]], q = [a; b], lo = -inf on the
// equality rows and 0 on the complementarity rows, hi = +inf. The header is two storage flags,
// n and m. Storage 1 gives the row blocks (starts, then a 0/1 complementarity flag per block:
// an equality block's rows are free) and M as a Siconos matrix (dense or sparse block, column
// by column) with q; storage 2 gives A, B, C, D (each row by row), a and b, with the n
// equalities first. A file with both is read from storage 1 and must agree with storage 2 to
// 1e-12 relative (the printed digits); a rectangular M (more equations than unknowns) is an
// UnsupportedProblem, since the canonical form pairs each row with one unknown.
//
// Every reader runs the guards of mlcp/input_limits.hpp (regular files of at most 256 MiB, JSON
// nesting of at most 64 levels, messages that quote at most 60 characters of the input) and
// takes entries of A and b, and finite bounds, of magnitude at most 1e100: products of two
// entries and sums of many such products stay finite.
//
// Errors are thrown as FormatError, whose message names the file and what is wrong. A file
// that parses but describes an invalid problem (lo > hi, findex out of range, ...) is reported
// too: readers return only problems that pass Problem::validate().
#pragma once

#include <stdexcept>
#include <string>

#include "mlcp/problem.hpp"

namespace mlcp::io {

struct FormatError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// A well-formed file describing a problem the canonical form cannot hold (a rectangular MLCP).
struct UnsupportedProblem : FormatError {
  using FormatError::FormatError;
};

// Reads mlcp-problem/1 JSON.
Problem readProblemJson(const std::string& path);
Problem parseProblemJson(const std::string& text, const std::string& sourceName = "<string>");
// Writes mlcp-problem/1 JSON (dense rows or sparse triplets, as the problem is stored).
void writeProblemJson(const Problem& problem, const std::string& path);
std::string problemToJson(const Problem& problem);

// Reads a Siconos LCP .dat file (dense or sparse-block storage).
Problem readSiconosLcp(const std::string& path);
Problem parseSiconosLcp(const std::string& text, const std::string& sourceName = "<string>");

// Reads a Siconos MLCP .dat file (storage 1, storage 2, or both).
Problem readSiconosMlcp(const std::string& path);
// Whether readProblem takes the file for a Siconos MLCP file: its name ends in "mlcp.dat".
bool isSiconosMlcpName(const std::string& path);

// Reads any kind, chosen by the file's name: "*mlcp.dat" Siconos MLCP, "*.dat" Siconos LCP,
// otherwise mlcp-problem/1 JSON.
Problem readProblem(const std::string& path);

// Reads a vector: a JSON array of numbers, or an object holding one under "x".
Vector readVectorJson(const std::string& path);

}  // namespace mlcp::io
