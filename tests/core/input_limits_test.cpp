// The readers' guards (mlcp/input_limits.hpp) and the problem files that once crashed or flooded
// a reader (tests/data/fuzz/problem_*): each is now a FormatError of one short line.
#include "mlcp/input_limits.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "mlcp/io.hpp"

namespace mlcp {
namespace {

const std::string kFuzzData = std::string(MLCP_SOURCE_DIR) + "/tests/data/fuzz/";

// The message of the FormatError that reading `path` throws ("" if none).
std::string readError(const std::string& path) {
  try {
    io::readProblem(path);
  } catch (const io::FormatError& e) {
    return e.what();
  }
  return "";
}

void expectShortError(const std::string& path, const std::string& fragment) {
  const std::string e = readError(path);
  EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
  EXPECT_NE(e.find(fragment), std::string::npos) << e;
  EXPECT_LE(e.size(), path.size() + 200) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

TEST(ProblemFuzzRegression, NumberOverflow1e309) {
  expectShortError(kFuzzData + "problem_number_overflow_1e309.json",
                   "not valid JSON: number overflow");
}

TEST(ProblemFuzzRegression, Entry1e300IsOutOfRange) {
  expectShortError(kFuzzData + "problem_entry_1e300.json",
                   "A[0][0] = 1e+300 is outside [-1e100, 1e100]");
}

TEST(ProblemFuzzRegression, Nested5000Levels) {
  expectShortError(kFuzzData + "problem_nested_5000.json", "JSON nested deeper than 64 levels");
}

TEST(ProblemFuzzRegression, SparseN1e8IsRefusedBeforeAllocating) {
  expectShortError(kFuzzData + "problem_sparse_n_1e8.json", "\"b\" has 0 entries");
}

TEST(ProblemFuzzRegression, SiconosN1e7IsRefusedBeforeAllocating) {
  expectShortError(kFuzzData + "problem_siconos_n_1e7.dat", "n = 10000000 is out of range");
}

TEST(ProblemFuzzRegression, SiconosBillionBlocksAreRefusedBeforeAllocating) {
  expectShortError(kFuzzData + "problem_siconos_blocks_1e9.dat", "out of range");
}

TEST(InputFiles, OnlyRegularFilesAreRead) {
  expectShortError("/dev/zero", "not a regular file");
  expectShortError("/dev/urandom", "not a regular file");
  expectShortError(MLCP_SOURCE_DIR, "not a regular file");
  expectShortError("/no/such/file.json", "cannot open file");
}

TEST(InputFiles, SizeLimitIsCheckedBeforeReading) {
  const std::string path =
      ::testing::TempDir() + "mlcp_input_limit_" + std::to_string(::getpid()) + ".json";
  std::ofstream(path) << std::string(100, ' ');
  EXPECT_EQ(io::readInputFile(path, 100, "test file").size(), 100u);
  try {
    io::readInputFile(path, 99, "test file");
    ADD_FAILURE() << "no error";
  } catch (const io::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("larger than the test file limit"), std::string::npos)
        << e.what();
  }
  std::filesystem::remove(path);
}

TEST(InputFiles, NestingLimitIs64Levels) {
  const auto nested = [](int d) { return std::string(d, '[') + std::string(d, ']'); };
  EXPECT_NO_THROW(io::checkJsonNesting(nested(io::kMaxJsonDepth), "t.json"));
  EXPECT_THROW(io::checkJsonNesting(nested(io::kMaxJsonDepth + 1), "t.json"), io::FormatError);
  // Brackets inside strings (escaped quotes too) do not count.
  EXPECT_NO_THROW(io::checkJsonNesting("[\"" + nested(100) + "\\\"" + nested(100) + "\"]", "t"));
}

TEST(InputFiles, MessagesEchoAtMost60Characters) {
  EXPECT_EQ(io::capped("short"), "short");
  EXPECT_EQ(io::capped(std::string(1000, 'x')).size(), io::kMaxEchoChars);
  EXPECT_EQ(io::capped(std::string(1000, '\n')).size(), io::kMaxEchoChars);
  // A megabyte string where a number belongs: the message stays short.
  const std::string text = R"({"format": "mlcp-problem/1", "n": 1, "A": [[1]], "b": [")" +
                           std::string(1 << 20, 'x') + "\"]}";
  try {
    io::parseProblemJson(text, "t.json");
    ADD_FAILURE() << "no error";
  } catch (const io::FormatError& e) {
    EXPECT_LT(std::string(e.what()).size(), 200u) << std::string(e.what()).substr(0, 300);
  }
  // And a megabyte token where the JSON syntax breaks.
  try {
    io::parseProblemJson("[" + std::string(1 << 20, '7') + "x", "t.json");
    ADD_FAILURE() << "no error";
  } catch (const io::FormatError& e) {
    EXPECT_LT(std::string(e.what()).size(), 200u) << std::string(e.what()).substr(0, 300);
  }
}

}  // namespace
}  // namespace mlcp
