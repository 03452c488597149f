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
// dense (storage 0) and sparse-block (storage 1) matrices, see ../shared/data/siconos/README.md.
// Both store their values column by column (the dense form prints one column per line).
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

// Reads mlcp-problem/1 JSON.
Problem readProblemJson(const std::string& path);
Problem parseProblemJson(const std::string& text, const std::string& sourceName = "<string>");
// Writes mlcp-problem/1 JSON (dense rows or sparse triplets, as the problem is stored).
void writeProblemJson(const Problem& problem, const std::string& path);
std::string problemToJson(const Problem& problem);

// Reads a Siconos LCP .dat file (dense or sparse-block storage).
Problem readSiconosLcp(const std::string& path);
Problem parseSiconosLcp(const std::string& text, const std::string& sourceName = "<string>");

// Reads either kind, chosen by the file's extension (.json or .dat).
Problem readProblem(const std::string& path);

// Reads a vector: a JSON array of numbers, or an object holding one under "x".
Vector readVectorJson(const std::string& path);

}  // namespace mlcp::io
