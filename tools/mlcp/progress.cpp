#include "progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>

namespace mlcp::cli {

Progress::Progress(std::string title, int total, bool quiet)
    : title_(std::move(title)),
      total_(std::max(total, 1)),
      quiet_(quiet),
      tty_(isatty(fileno(stderr)) != 0),
      begin_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { finish(); }

double Progress::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - begin_).count();
}

void Progress::start(const std::string& label) {
  label_ = label;
  if (tty_) draw();
}

void Progress::done() {
  done_ = std::min(done_ + 1, total_);
  if (tty_) {
    draw();
  } else if (!quiet_ && done_ * 10 / total_ != lastTenth_) {
    lastTenth_ = done_ * 10 / total_;
    std::cerr << title_ << ": " << done_ << "/" << total_ << " (" << label_ << ")\n";
  }
}

void Progress::draw() {
  if (quiet_) return;
  constexpr int kWidth = 24;
  const int filled = done_ * kWidth / total_;
  const double s = seconds();
  char eta[32] = "";
  if (done_ > 0 && done_ < total_)
    std::snprintf(eta, sizeof eta, ", ~%.0f s left", s / done_ * (total_ - done_));
  // \033[K clears what a longer previous label left behind.
  std::cerr << '\r' << title_ << " [" << std::string(filled, '#')
            << std::string(kWidth - filled, '.') << "] " << done_ << "/" << total_ << " " << label_
            << " (" << static_cast<int>(s) << " s" << eta << ")\033[K" << std::flush;
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (quiet_) return;
  char line[64];
  std::snprintf(line, sizeof line, "%d/%d in %.1f s", done_, total_, seconds());
  if (tty_) std::cerr << "\r\033[K";
  std::cerr << title_ << ": " << line << "\n";
}

}  // namespace mlcp::cli
