// mlcp/input_limits.hpp: the guards every file reader runs before it parses anything.
//
// A reader of problem files, scene files or trajectories takes its text through readInputFile()
// and, for JSON, runs checkJsonNesting() before it parses and jsonErrorText() on what the JSON
// library throws (syntax errors, and numbers beyond the range of a double such as "1e309",
// which it throws as out_of_range, not parse_error: a reader catches every nlohmann::json
// exception). Together they make every bad input a FormatError with one short line
// "<file>: <what>", never a crash, a hang or a flood:
//
// - only regular files are read (not /dev/zero, a FIFO, a directory), and only up to a size
//   limit per kind of file, checked before a byte is read: endless or huge inputs stop at once;
// - JSON nesting deeper than kMaxJsonDepth is refused by a linear scan before parsing (the
//   formats need 4 to 6 levels; a value nested thousands deep would otherwise reach the
//   recursive dump of an error message and overflow the stack);
// - whatever a message echoes from the input goes through capped(), at most kMaxEchoChars
//   characters, so a message is always one short line.
//
// Cost: one stat, one read, one pass over the text for the nesting depth.
#pragma once

#include <cstddef>
#include <exception>
#include <string>

#include "mlcp/io.hpp"

namespace mlcp::io {

// Largest files read, in bytes. Problem files: 256 MiB holds a dense problem of n = 3000
// written at full precision (9 million numbers) or a sparse one of some 7 million non-zeros.
inline constexpr std::size_t kMaxProblemFileBytes = std::size_t(256) << 20;
// Scene files: 16 MiB is some 100 000 explicit bodies (the scene's body limit); generators keep
// real scenes at a few kB.
inline constexpr std::size_t kMaxSceneFileBytes = std::size_t(16) << 20;
// Trajectory CSV files (mlcp diff): 1 GiB is 600 steps of a 10 000-body scene.
inline constexpr std::size_t kMaxTrajectoryFileBytes = std::size_t(1) << 30;
// Deepest nesting of arrays and objects in a JSON input (the formats need at most 6).
inline constexpr int kMaxJsonDepth = 64;
// Most characters of the input a message quotes.
inline constexpr std::size_t kMaxEchoChars = 60;

// Throws FormatError("<path>: <what>") unless path names a readable regular file of at most
// maxBytes bytes. `what` names the kind of file in the message ("problem file").
void checkInputFile(const std::string& path, std::size_t maxBytes, const char* what);
// checkInputFile(), then the whole file.
std::string readInputFile(const std::string& path, std::size_t maxBytes, const char* what);

// Throws FormatError("<source>: JSON nested deeper than 64 levels (line L)") when arrays and
// objects in text nest deeper than kMaxJsonDepth (strings are skipped; the text need not be
// valid JSON, the parser judges that afterwards).
void checkJsonNesting(const std::string& text, const std::string& source);

// "not valid JSON: <the library's message without its [json.exception...] tag>", capped to
// one short line.
std::string jsonErrorText(const std::exception& e);

// s with its control characters escaped (a newline as \n, others as \xHH: an echoed key or name
// never breaks the message's line), itself when at most maxChars long, else its first
// maxChars - 3 characters and "...".
std::string capped(const std::string& s, std::size_t maxChars = kMaxEchoChars);

// text read whole as a number (std::stod: decimal, hex, inf, nan), NaN when it is empty or
// anything follows the number: what command-line values are checked with.
double parseNumber(const std::string& text);

}  // namespace mlcp::io
