#include "forked_jobs.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <thread>
#include <vector>

namespace mlcp::cli {

namespace {

struct Child {
  pid_t pid = -1;
  int fd = -1;  // the read end of the child's pipe
  std::size_t task = 0;
  std::string bytes;
};

bool writeAll(int fd, const std::string& bytes) {
  std::size_t at = 0;
  while (at < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + at, bytes.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    at += static_cast<std::size_t>(n);
  }
  return true;
}

// Exit statuses of a child: its answer written, an exception's message written instead (the
// task threw), or the pipe failed.
constexpr int kAnswered = 0, kThrew = 86, kUnsent = 87;

// In the child: the task, its answer written, the end. The child never returns into the
// parent's code, not even by an exception (that would run the rest of the parent's program in
// the child).
[[noreturn]] void childMain(int fd, std::size_t task,
                            const std::function<std::string(std::size_t)>& work) {
  int status = kAnswered;
  std::string bytes;
  try {
    bytes = work(task);
  } catch (const std::exception& e) {
    bytes = e.what(), status = kThrew;
  } catch (...) {
    bytes = "an exception of unknown type", status = kThrew;
  }
  const bool sent = writeAll(fd, bytes);
  std::cout.flush();  // what the task printed (the buffers were empty at the fork)
  std::cerr.flush();
  std::fflush(nullptr);
  _exit(sent ? status : kUnsent);
}

Child start(std::size_t task, const std::function<std::string(std::size_t)>& work) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw std::runtime_error(std::string("cannot make a pipe: ") + std::strerror(errno));
  std::cout.flush();  // a child must not inherit (and later write) the parent's buffered output
  std::cerr.flush();
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::runtime_error(std::string("cannot start a worker process: ") + std::strerror(err));
  }
  if (pid == 0) {
    ::close(fds[0]);
    childMain(fds[1], task, work);
  }
  ::close(fds[1]);
  return {pid, fds[0], task, {}};
}

// The child's pipe is at its end: its exit status read, its outcome.
ForkedOutcome reap(Child& child) {
  ::close(child.fd);
  int status = 0;
  while (::waitpid(child.pid, &status, 0) < 0 && errno == EINTR) {
  }
  ForkedOutcome out{std::move(child.bytes), ""};
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* name = strsignal(sig);
    out.crash =
        "killed by signal " + std::to_string(sig) + (name ? std::string(" (") + name + ")" : "");
  } else if (WIFEXITED(status) && WEXITSTATUS(status) == kThrew) {
    out.crash = "threw: " + out.bytes;
  } else if (WIFEXITED(status) && WEXITSTATUS(status) != kAnswered) {
    out.crash = "exited with status " + std::to_string(WEXITSTATUS(status));
  }
  if (!out.crash.empty()) out.bytes.clear();
  return out;
}

// Reads what the children have written; moves those whose pipes ended to `ended`.
void readChildren(std::vector<Child>& running, std::vector<Child>& ended) {
  std::vector<pollfd> fds;
  for (const Child& c : running) fds.push_back({c.fd, POLLIN, 0});
  if (::poll(fds.data(), fds.size(), -1) < 0) {
    if (errno == EINTR) return;
    throw std::runtime_error(std::string("poll: ") + std::strerror(errno));
  }
  char buffer[65536];
  for (std::size_t k = fds.size(); k-- > 0;) {
    if (fds[k].revents == 0) continue;
    const ssize_t n = ::read(fds[k].fd, buffer, sizeof buffer);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n > 0) {
      running[k].bytes.append(buffer, static_cast<std::size_t>(n));
      continue;
    }
    ended.push_back(std::move(running[k]));
    running.erase(running.begin() + static_cast<std::ptrdiff_t>(k));
  }
}

}  // namespace

void runForked(std::size_t count, int jobs, const std::function<std::string(std::size_t)>& work,
               const std::function<void(std::size_t)>& onStart,
               const std::function<bool(std::size_t, ForkedOutcome&&)>& onDone) {
  std::vector<Child> running;
  std::size_t next = 0;
  bool starting = true;
  try {
    while (true) {
      while (starting && next < count && running.size() < static_cast<std::size_t>(jobs)) {
        running.push_back(start(next, work));
        onStart(next++);
      }
      if (running.empty()) return;
      std::vector<Child> ended;
      readChildren(running, ended);
      for (Child& child : ended) {
        const std::size_t task = child.task;
        if (!onDone(task, reap(child))) starting = false;
      }
    }
  } catch (...) {  // no child outlives the parent's error
    for (Child& child : running) {
      ::kill(child.pid, SIGKILL);
      reap(child);
    }
    throw;
  }
}

int resolveJobs(int jobs) {
  if (jobs > 0) return jobs;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace mlcp::cli
