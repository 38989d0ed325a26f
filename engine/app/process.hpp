// process.hpp: running one program with a real timeout, for the grader.
//
// A grading case, the build of a student's submission, or a program `clothlab bench` runs (the
// plot script, the student build), runs as a child process in its own process group, with its
// output captured: the one way this program starts another. When the time is up, or when the grader
// is interrupted (Ctrl-C, or a TERM from an autograder), the whole group is killed, so no orphan
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
  std::string events;  // what it wrote to kEventsFd, when asked for
  int exit_code = 0;   // meaningful when signal == 0 and the run was not cut off
  int signal = 0;
  bool timed_out = false;
  bool interrupted = false;
};

// At most 1 MiB of a chatty child's output is kept, and 4 MiB of its events: an honest case that
// prints a lot is still judged on what its reporter said, which comes through a pipe of its own.
constexpr std::size_t kMaxOutput = 1 << 20;
constexpr std::size_t kMaxEvents = 4 << 20;
// The descriptor a grading binary writes its events to (it is told so by CLOTHLAB_EVENTS_FD).
constexpr int kEventsFd = 3;

// Limits set on the child (setrlimit) before it runs, inherited by whatever it starts; 0 leaves
// a limit as it is. A child that passes one is stopped by the kernel: out of memory (an
// allocation fails), SIGXCPU, or SIGXFSZ.
struct ProcessLimits {
  std::size_t memory_bytes = 0;  // address space (RLIMIT_AS)
  double cpu_seconds = 0;        // processor time (RLIMIT_CPU)
  std::size_t file_bytes = 0;    // size of any file it writes (RLIMIT_FSIZE)
};

// Runs args[0] (a path, or a name looked for on the PATH) with args, stdin from /dev/null, for at
// most timeout [s], with this process's environment and `env` ("NAME=value", in place of the same
// names). With `events`, the child also gets a pipe of its own as descriptor kEventsFd (and
// CLOTHLAB_EVENTS_FD=3 in its environment), read into ProcessResult::events.
// Whatever the child started ends with it: its process group is killed when it ends, and so is
// any process that left the group (setsid) and was handed to this one when its parent died.
ProcessResult run_process(const std::vector<std::string>& args, double timeout,
                          const ProcessLimits& limits = {},
                          const std::vector<std::string>& env = {}, bool events = false);

// Makes this process the one that orphans of its children are handed to (a "subreaper"), so that
// run_process can end them. Called once by the grader before it runs anything.
void adopt_orphans();

}  // namespace clothlab::app
