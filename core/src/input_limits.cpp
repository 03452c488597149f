#include "mlcp/input_limits.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

namespace mlcp::io {

namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw FormatError(source + ": " + what);
}

std::string mebibytes(std::size_t bytes) {
  std::ostringstream os;
  os << double(bytes) / double(1 << 20) << " MiB";
  return os.str();
}

}  // namespace

void checkInputFile(const std::string& path, std::size_t maxBytes, const char* what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) fail(path, "cannot open file");
  if (!fs::is_regular_file(st))
    fail(path, std::string("not a regular file (a ") + what + " must be one)");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) fail(path, "cannot read the file size");
  if (size > maxBytes)
    fail(path, std::string("file of ") + mebibytes(size) + " is larger than the " + what +
                   " limit of " + mebibytes(maxBytes));
}

std::string readInputFile(const std::string& path, std::size_t maxBytes, const char* what) {
  checkInputFile(path, maxBytes, what);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  // Stops past maxBytes, so a file that grows after the check is caught all the same.
  std::string out;
  std::vector<char> chunk(std::size_t(1) << 16);
  while (in) {
    in.read(chunk.data(), std::streamsize(chunk.size()));
    out.append(chunk.data(), std::size_t(in.gcount()));
    if (out.size() > maxBytes)
      fail(path,
           std::string("file is larger than the ") + what + " limit of " + mebibytes(maxBytes));
  }
  return out;
}

void checkJsonNesting(const std::string& text, const std::string& source) {
  int depth = 0;
  long long line = 1;
  bool inString = false, escaped = false;
  for (char c : text) {
    if (c == '\n') ++line;
    if (inString) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        inString = false;
      continue;
    }
    if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        fail(source, "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels (line " +
                         std::to_string(line) + ")");
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

std::string jsonErrorText(const std::exception& e) {
  std::string what = e.what();
  // nlohmann's messages start with "[json.exception.parse_error.101] ".
  const auto close = what.find("] ");
  if (what.rfind("[json.exception", 0) == 0 && close != std::string::npos)
    what = what.substr(close + 2);
  std::replace(what.begin(), what.end(), '\n', ' ');
  return "not valid JSON: " + capped(what, 2 * kMaxEchoChars);
}

double parseNumber(const std::string& text) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  return used != 0 && used == text.size() ? v : std::numeric_limits<double>::quiet_NaN();
}

std::string capped(const std::string& s, std::size_t maxChars) {
  std::string out;
  for (const char c : s) {
    if (out.size() > maxChars) break;
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (u < 0x20 || u == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", u);
      out += hex;
    } else {
      out += c;
    }
  }
  if (out.size() <= maxChars) return out;
  return out.substr(0, maxChars > 3 ? maxChars - 3 : 0) + "...";
}

}  // namespace mlcp::io
