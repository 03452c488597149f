// Problem files: round trips and clear errors for malformed files.
#include "mlcp/io.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/generators.hpp"

namespace mlcp {
namespace {

std::string errorOf(const std::string& text) {
  try {
    io::parseProblemJson(text, "t.json");
  } catch (const io::FormatError& e) {
    return e.what();
  }
  return "";
}

void expectError(const std::string& text, const std::string& fragment) {
  const std::string e = errorOf(text);
  EXPECT_NE(e.find("t.json: "), std::string::npos) << e;
  EXPECT_NE(e.find(fragment), std::string::npos) << "error was '" << e << "'";
}

TEST(ProblemJson, ReadsDenseWithDefaults) {
  const Problem p = io::parseProblemJson(
      R"({"format": "mlcp-problem/1", "n": 2, "A": [[2, 1], [1, 2]], "b": [-1, -1]})");
  EXPECT_EQ(p.size(), 2);
  EXPECT_FALSE(p.isSparse());
  EXPECT_EQ(p.lo, Vector::Zero(2));
  EXPECT_EQ(p.hi[1], kInf);
  EXPECT_EQ(p.classify(), ProblemClass::StandardLcp);
}

TEST(ProblemJson, ReadsSparseTripletsSummingDuplicates) {
  const Problem p = io::parseProblemJson(
      R"({"format": "mlcp-problem/1", "n": 2,
          "A": {"rows": 2, "cols": 2, "triplets": [[0, 0, 1], [0, 0, 2], [1, 1, 4]]},
          "b": [0, 0], "lo": ["-inf", -1], "hi": ["inf", 1], "findex": [-1, -1]})");
  EXPECT_TRUE(p.isSparse());
  EXPECT_EQ(p.diagonal(0), 3);
  EXPECT_EQ(p.lo[0], -kInf);
  EXPECT_EQ(p.hi[1], 1);
}

TEST(ProblemJson, RoundTripsExactly) {
  test::Generator g(5);
  test::KnownProblem kp = g.friction(3);
  for (bool sparse : {false, true}) {
    Problem p = kp.problem;
    if (sparse) p.setA(p.toSparse());
    const Problem q = io::parseProblemJson(io::problemToJson(p));
    EXPECT_EQ(q.isSparse(), sparse);
    EXPECT_EQ(q.toDense(), p.toDense());
    EXPECT_EQ(q.b, p.b);
    EXPECT_EQ(q.lo, p.lo);
    EXPECT_EQ(q.hi, p.hi);
    EXPECT_EQ(q.findex, p.findex);
  }
}

TEST(ProblemJson, MalformedFilesNameTheProblem) {
  expectError("{", "not valid JSON");
  expectError("[1, 2]", "top level must be a JSON object");
  expectError(R"({"n": 1, "A": [[1]], "b": [0]})", "\"format\"");
  expectError(R"({"format": "mlcp-problem/1", "n": -1, "A": [], "b": []})", "\"n\"");
  expectError(R"({"format": "mlcp-problem/1", "n": 1, "b": [0]})", "missing \"A\"");
  expectError(R"({"format": "mlcp-problem/1", "n": 2, "A": [[1, 0]], "b": [0, 0]})",
              "\"A\" has 1 rows");
  expectError(R"({"format": "mlcp-problem/1", "n": 1, "A": [["x"]], "b": [0]})",
              "A[0][0] is not a number");
  expectError(R"({"format": "mlcp-problem/1", "n": 1, "A": [[1]], "b": [0, 1]})",
              "\"b\" has 2 entries");
  expectError(R"({"format": "mlcp-problem/1", "n": 1, "A": [[1]]})", "missing \"b\"");
  expectError(R"({"format": "mlcp-problem/1", "n": 1, "A": [[1]], "b": [0], "lo": ["nan"]})",
              "lo[0]");
  expectError(R"({"format": "mlcp-problem/1", "n": 1, "A": [[1]], "b": [0], "lo": [2], "hi": [1]})",
              "lo = 2 > hi = 1");
  expectError(
      R"({"format": "mlcp-problem/1", "n": 2, "A": [[1, 0], [0, 1]], "b": [0, 0], "findex": [-1, 5]})",
      "findex[1] = 5 is out of range");
  expectError(
      R"({"format": "mlcp-problem/1", "n": 1, "A": {"rows": 1, "cols": 1, "triplets": [[0, 3, 1]]}, "b": [0]})",
      "outside");
  expectError(
      R"({"format": "mlcp-problem/1", "n": 1, "A": {"rows": 2, "cols": 1, "triplets": []}, "b": [0]})",
      "n x n");
  expectError(R"({"format": "mlcp-problem/1", "n": 1, "A": [[1e999]], "b": [0]})", "");
}

TEST(ProblemJson, MissingFile) {
  EXPECT_THROW(io::readProblemJson("/nonexistent/p.json"), io::FormatError);
}

const std::string kSiconos = MLCP_SICONOS_DIR;

TEST(Siconos, DenseAndBlockFilesAgree) {
  for (const char* name : {"deudeu", "ortiz", "trivial"}) {
    const Problem dense = io::readSiconosLcp(kSiconos + "/lcp/lcp_" + name + ".dat");
    const Problem block = io::readSiconosLcp(kSiconos + "/lcp/lcp_" + name + "_block.dat");
    EXPECT_FALSE(dense.isSparse());
    EXPECT_TRUE(block.isSparse());
    EXPECT_EQ(dense.toDense(), block.toDense()) << name;
    EXPECT_EQ(dense.b, block.b) << name;
  }
}

TEST(Siconos, ReadsKnownValues) {
  const Problem p = io::readSiconosLcp(kSiconos + "/lcp/lcp_deudeu.dat");
  ASSERT_EQ(p.size(), 2);
  EXPECT_EQ(p.denseA()(0, 1), 1);
  EXPECT_EQ(p.b[0], -5);
  EXPECT_EQ(p.b[1], -6);
}

TEST(Siconos, TruncatedAndGarbledFiles) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("mlcp_io_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto attempt = [&](const std::string& text) -> std::string {
    const std::string path = (dir / "bad.dat").string();
    std::ofstream(path) << text;
    try {
      io::readSiconosLcp(path);
    } catch (const io::FormatError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(attempt("2\n0\n2\n2\n2 2\n1 0\n0 1\n-1\n").find("file ends before"), std::string::npos);
  EXPECT_NE(attempt("2\n7\n").find("storage type 7"), std::string::npos);
  EXPECT_NE(attempt("2\n0\n3\n3\n3 3\n").find("expected 2x2"), std::string::npos);
  EXPECT_NE(attempt("2\n0\n2\n2\n2 2\n1 x\n0 1\n-1 -1\n").find("got 'x'"), std::string::npos);
  EXPECT_NE(attempt("-3\n0\n").find("out of range"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// deudeu_mlcp: n = m = 1, M = [[1, -1], [0, 1]] (printed column by column), q = (-1, 1), and
// storage 2 with the same blocks printed row by row.
TEST(SiconosMlcp, ReadsKnownValuesAndBounds) {
  const Problem p = io::readSiconosMlcp(kSiconos + "/mlcp/deudeu_mlcp.dat");
  ASSERT_EQ(p.size(), 2);
  const DenseMatrix A = p.toDense();
  EXPECT_EQ(A(0, 0), 1);
  EXPECT_EQ(A(0, 1), -1);
  EXPECT_EQ(A(1, 0), 0);
  EXPECT_EQ(A(1, 1), 1);
  EXPECT_EQ(p.b[0], -1);
  EXPECT_EQ(p.b[1], 1);
  EXPECT_EQ(p.lo[0], -kInf);  // the equality row is free
  EXPECT_EQ(p.lo[1], 0);
  EXPECT_EQ(p.hi[1], kInf);
}

// Every file with both storages is checked against itself by the reader; the asymmetric
// circuit matrices tell row-by-row from column-by-column reading apart.
TEST(SiconosMlcp, EveryCorpusFileReadsOrIsUnsupported) {
  int read = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kSiconos + "/mlcp")) {
    const std::string path = entry.path().string();
    ASSERT_TRUE(io::isSiconosMlcpName(path)) << path;
    if (entry.path().stem() == "Rectangular_mlcp") {
      EXPECT_THROW(io::readProblem(path), io::UnsupportedProblem);
      continue;
    }
    const Problem p = io::readProblem(path);
    EXPECT_TRUE(p.validate().empty()) << path;
    EXPECT_GT((p.lo.array() == -kInf).count(), 0) << path;
    ++read;
  }
  EXPECT_EQ(read, 15);
}

TEST(SiconosMlcp, StorageTwoAloneAndDisagreeingStorages) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("mlcp_mlcp_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "case_mlcp.dat").string();
  auto attempt = [&](const std::string& text) -> std::string {
    std::ofstream(path) << text;
    try {
      io::readProblem(path);
    } catch (const io::FormatError& e) {
      return e.what();
    }
    return "";
  };
  // Storage 2 only: A = 2, B = 3, C = 1, D = -1, a = 4, b = 5.
  EXPECT_EQ(attempt("0 1 1 1\n2\n3\n1\n-1\n4\n5\n"), "");
  const Problem p = io::readProblem(path);
  EXPECT_EQ(p.toDense(), (DenseMatrix(2, 2) << 2, 1, -1, 3).finished());
  EXPECT_EQ(p.b, (Vector(2) << 4, 5).finished());
  EXPECT_EQ(p.lo[0], -kInf);
  EXPECT_EQ(p.lo[1], 0);
  // Both storages, C and D exchanged in storage 2.
  EXPECT_NE(attempt("1 1 1 1\n0 1 2\n0 1\n0 2 2 2 2\n2 -1 1 3\n4 5\n2\n3\n-1\n1\n4\n5\n")
                .find("describe different problems"),
            std::string::npos);
  EXPECT_NE(attempt("1 0 1 1\n0 1 2\n0 7\n").find("flag is not 0 or 1"), std::string::npos);
  EXPECT_NE(attempt("1 0 2 1\n0 2 1\n").find("not increasing"), std::string::npos);
  EXPECT_NE(attempt("0 0 1 1\n").find("storage flags"), std::string::npos);
  EXPECT_NE(attempt("1 0 1 1\n0 1 2\n0 1\n0 3 2 3 2\n").find("rectangular"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mlcp
