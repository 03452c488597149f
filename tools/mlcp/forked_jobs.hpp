// Independent tasks in child processes, a few at a time: fork() per task, the task's answer back
// to the parent through a pipe. Processes, not threads: ODE and Bullet keep process-wide state,
// so two worlds may not be stepped from two threads at once. A forked child starts as a copy of the
// parent (scenes loaded, engines initialised), runs its task, writes its answer and ends with
// _exit, so nothing of the parent's (buffered streams, atexit handlers) runs twice. POSIX only.
//
// A child that dies (a signal, a non-zero exit) or whose task throws is reported to the caller
// with what ended it; it never takes the parent down.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace mlcp::cli {

struct ForkedOutcome {
  std::string bytes;  // what the task returned (complete only when `crash` is empty)
  // "" when the child wrote its answer and exited 0; else what ended it, e.g. "killed by signal
  // 11 (Segmentation fault)", "exited with status 3" or "threw: MESSAGE" (then `bytes` is "").
  std::string crash;
};

// Runs work(0), ..., work(count - 1), each in a child process of its own, at most `jobs`
// (>= 1) at a time, started in index order. In the parent: onStart(i) as task i's child starts,
// onDone(i, outcome) as it ends (in order of completion). onDone returning false starts no
// further task; those running are waited for and reported all the same. Throws
// std::runtime_error when no child process or pipe can be made.
void runForked(std::size_t count, int jobs, const std::function<std::string(std::size_t)>& work,
               const std::function<void(std::size_t)>& onStart,
               const std::function<bool(std::size_t, ForkedOutcome&&)>& onDone);

// What `jobs` means for a command's --jobs: 0 is every core (at least 1), else itself.
int resolveJobs(int jobs);

}  // namespace mlcp::cli
