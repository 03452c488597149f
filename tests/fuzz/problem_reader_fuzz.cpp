// libFuzzer target: the problem readers (mlcp-problem/1 JSON and Siconos LCP .dat) on any text.
// Invariant: a FormatError of one short line, or a problem that passes Problem::validate(); any
// other exception, a crash, a sanitizer report or a hang is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_checks.hpp"
#include "mlcp/io.hpp"

namespace {

template <class Parse>
void read(Parse parse, const std::string& text) {
  try {
    const mlcp::Problem p = parse(text, "fuzz");
    if (std::string why = p.validate(); !why.empty()) mlcp::fuzz::violated("invalid problem", why);
  } catch (const mlcp::io::FormatError& e) {
    mlcp::fuzz::checkMessage(e.what());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  read(mlcp::io::parseProblemJson, text);
  read(mlcp::io::parseSiconosLcp, text);
  return 0;
}
