// What every fuzz target checks of a reader's error: one line, short. A violation aborts, which
// libFuzzer reports as a crash and saves the input.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace mlcp::fuzz {

// Longest message a reader may give: the file name plus a path and a capped echo of the input.
inline constexpr std::size_t kMaxMessageChars = 400;

[[noreturn]] inline void violated(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz check failed: %s: %.300s\n", what, detail.c_str());
  std::abort();
}

inline void checkMessage(const std::string& message) {
  if (message.size() > kMaxMessageChars) violated("message longer than 400 characters", message);
  if (message.find('\n') != std::string::npos) violated("message of more than one line", message);
}

}  // namespace mlcp::fuzz
