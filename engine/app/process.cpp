// process.cpp: see process.hpp.
#include "app/process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <system_error>
#include <thread>

namespace clothlab::app {

using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_interrupted = 0;

namespace {
extern "C" void on_interrupt(int) {
  g_interrupted = 1;
}
}  // namespace

InterruptGuard::InterruptGuard() {
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: poll() must return EINTR so we notice at once
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

ProcessResult run_process(const std::vector<std::string>& args, double timeout) {
  // Built before fork(): the child may only make async-signal-safe calls.
  std::vector<char*> argv;
  for (const auto& a : args)
    argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::system_error(errno, std::generic_category(), "pipe");
  const pid_t pid = fork();
  if (pid < 0) throw std::system_error(errno, std::generic_category(), "fork");
  if (pid == 0) {
    setpgid(0, 0);  // its own process group: a timeout kills whatever the case started too
    // No terminal input: a background process group reading it would be stopped, not fail.
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0) dup2(null_fd, STDIN_FILENO);
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    execv(argv[0], argv.data());
    const char message[] = "clothlab grade: cannot execute the program\n";
    [[maybe_unused]] auto ignored = write(STDERR_FILENO, message, sizeof message - 1);
    _exit(127);
  }
  setpgid(pid, pid);  // also here, so the kill below cannot race the child's own call
  close(fds[1]);

  ProcessResult result;
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout);
  auto time_left_ms = [&] {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
    return std::max<long>(0, static_cast<long>(left.count()));
  };
  auto stop = [&](bool& reason) {
    kill(-pid, SIGKILL);
    reason = true;
  };

  // Read until end of file (the case and anything it started closed the pipe) or the deadline.
  char buffer[4096];
  for (;;) {
    if (g_interrupted) {
      stop(result.interrupted);
      break;
    }
    const long left = time_left_ms();
    if (left == 0) {
      stop(result.timed_out);
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(std::min<long>(left, 1000)));
    if (ready <= 0) continue;  // timeout slice or EINTR: check the deadline and the flag again
    const ssize_t got = read(fds[0], buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    if (result.output.size() < kMaxOutput) result.output.append(buffer, static_cast<size_t>(got));
  }
  close(fds[0]);

  // The pipe can close before the process ends: wait for it, still under the deadline.
  int status = 0;
  for (;;) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) break;
    if (!result.timed_out && !result.interrupted) {
      if (g_interrupted)
        stop(result.interrupted);
      else if (time_left_ms() == 0)
        stop(result.timed_out);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (WIFSIGNALED(status)) result.signal = WTERMSIG(status);
  if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  return result;
}

}  // namespace clothlab::app
