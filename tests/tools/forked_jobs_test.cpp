// Tasks in forked child processes (tools/mlcp/forked_jobs.hpp): answers of any size come back
// whole and in the task's slot, at most `jobs` children run at once, a child that dies or throws
// is reported with what ended it (the parent goes on, and so does no child past its task), and
// onDone can stop further starts.
#include "forked_jobs.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>

namespace mlcp::cli {
namespace {

std::string answer(std::size_t i) { return std::string(100000 + i, static_cast<char>('a' + i)); }

TEST(ForkedJobs, AnswersComeBackWholeAtMostJobsAtOnce) {
  std::map<std::size_t, ForkedOutcome> done;
  int running = 0, most = 0;
  runForked(
      6, 2, [](std::size_t i) { return answer(i); },
      [&](std::size_t) { most = std::max(most, ++running); },
      [&](std::size_t i, ForkedOutcome&& out) {
        --running;
        done[i] = std::move(out);
        return true;
      });
  EXPECT_EQ(most, 2);
  ASSERT_EQ(done.size(), 6u);
  for (const auto& [i, out] : done) {
    EXPECT_EQ(out.crash, "") << i;
    EXPECT_TRUE(out.bytes == answer(i)) << i << ": " << out.bytes.size() << " bytes";
  }
}

TEST(ForkedJobs, ADeadChildIsReportedAndTheOthersFinish) {
  std::map<std::size_t, ForkedOutcome> done;
  runForked(
      4, 2,
      [](std::size_t i) -> std::string {
        if (i == 1) std::abort();
        if (i == 2) throw std::runtime_error("thrown in the child");
        if (i == 3) std::_Exit(7);
        return "ok";
      },
      [](std::size_t) {},
      [&](std::size_t i, ForkedOutcome&& out) {
        done[i] = std::move(out);
        return true;
      });
  ASSERT_EQ(done.size(), 4u);
  EXPECT_EQ(done[0].crash, "");
  EXPECT_EQ(done[0].bytes, "ok");
  EXPECT_NE(done[1].crash.find("killed by signal"), std::string::npos) << done[1].crash;
  EXPECT_EQ(done[2].crash, "threw: thrown in the child");
  EXPECT_EQ(done[3].crash, "exited with status 7");
}

TEST(ForkedJobs, OnDoneFalseStartsNoMore) {
  std::vector<std::size_t> started;
  runForked(
      6, 1, [](std::size_t) { return std::string("x"); },
      [&](std::size_t i) { started.push_back(i); },
      [](std::size_t i, ForkedOutcome&&) { return i < 2; });
  EXPECT_EQ(started, (std::vector<std::size_t>{0, 1, 2}));
}

TEST(ForkedJobs, ZeroJobsIsEveryCore) {
  EXPECT_GE(resolveJobs(0), 1);
  EXPECT_EQ(resolveJobs(3), 3);
}

}  // namespace
}  // namespace mlcp::cli
