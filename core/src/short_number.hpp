// shortNumber(x): x as `std::ostream << x` writes it (printf's %g, 6 significant digits), made
// by std::to_chars, without a stream. Messages on paths that end well (a solve that converged
// after a breakdown, an engine island's report) hold numbers, and an std::ostringstream's
// locale set-up and num_put cost more than a tiny problem's whole solve.
#pragma once

#include <charconv>
#include <string>

namespace mlcp::detail {

inline std::string shortNumber(double x) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, x, std::chars_format::general, 6).ptr;
  return std::string(text, end);
}

}  // namespace mlcp::detail
