// A progress bar on stderr for the long scene commands (sweep, stability): one line redrawn in
// place on a terminal, a plain line every tenth of the work otherwise (CI logs stay short).
//
//     Progress bar("stability", cells);
//     for (...) { bar.start(label); ...; bar.done(); }
//     bar.finish();   // "stability: 48/48 in 31.2 s"
#pragma once

#include <chrono>
#include <iosfwd>
#include <string>

namespace mlcp::cli {

class Progress {
 public:
  // `total` units of work; `quiet` prints nothing at all.
  Progress(std::string title, int total, bool quiet = false);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Names the unit now running (shown on a terminal).
  void start(const std::string& label);
  // One unit finished.
  void done();
  // Ends the bar with the total time (also run by the destructor).
  void finish();
  double seconds() const;

 private:
  void draw();

  std::string title_, label_;
  int total_, done_ = 0;
  int lastTenth_ = -1;
  bool quiet_, tty_, finished_ = false;
  std::chrono::steady_clock::time_point begin_;
};

}  // namespace mlcp::cli
