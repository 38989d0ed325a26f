// process.hpp: running one program with a real timeout, for the grader.
//
// A grading case, or the build of a student's submission, runs as a child process in its own
// process group, with its output captured. When the time is up, or when the grader is
// interrupted (Ctrl-C, or a TERM from an autograder), the whole group is killed, so no orphan
// keeps running.
#pragma once

#include <csignal>
#include <cstddef>
#include <string>
#include <vector>

namespace clothlab::app {

// Set by the InterruptGuard's handler; the grader stops starting new work once it is set.
extern volatile std::sig_atomic_t g_interrupted;

// While alive, SIGINT and SIGTERM set g_interrupted instead of ending the grader, so the
// results written so far stay valid and the running child is killed, not orphaned.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

struct ProcessResult {
  std::string output;  // stdout and stderr, interleaved as written
  int exit_code = 0;   // meaningful when signal == 0 and the run was not cut off
  int signal = 0;
  bool timed_out = false;
  bool interrupted = false;
};

constexpr std::size_t kMaxOutput = 1 << 20;  // keep at most 1 MiB of a chatty child's output

// Runs args[0] (an absolute path) with args, stdin from /dev/null, for at most timeout [s].
ProcessResult run_process(const std::vector<std::string>& args, double timeout);

}  // namespace clothlab::app
