// process.cpp: see process.hpp.
#include "app/process.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string_view>
#include <system_error>
#include <thread>

namespace clothlab::app {

using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_interrupted = 0;

namespace {
extern "C" void on_interrupt(int) {
  g_interrupted = 1;
}

// The children of this process, read from /proc: after a case has ended, any that is left is an
// orphan a case left behind (see adopt_orphans).
std::vector<pid_t> children() {
  std::vector<pid_t> found;
  const pid_t self = getpid();
  DIR* dir = opendir("/proc");
  if (dir == nullptr) return found;
  while (const dirent* entry = readdir(dir)) {
    const pid_t pid = static_cast<pid_t>(std::atol(entry->d_name));
    if (pid <= 0) continue;
    std::ifstream stat("/proc/" + std::string(entry->d_name) + "/stat");
    std::string text;
    std::getline(stat, text);
    // "pid (comm) state ppid ...": comm may hold spaces and parentheses, so read after the last
    // ')'.
    const auto close = text.rfind(')');
    if (close == std::string::npos) continue;
    char state = 0;
    long ppid = 0;
    if (std::sscanf(text.c_str() + close + 1, " %c %ld", &state, &ppid) == 2 && ppid == self)
      found.push_back(pid);
  }
  closedir(dir);
  return found;
}

// Ends every process handed to this one, and whatever they started in turn, until none is left.
void end_orphans() {
  for (int round = 0; round < 100; ++round) {
    const std::vector<pid_t> left = children();
    if (left.empty()) return;
    for (const pid_t pid : left) {
      kill(-pid, SIGKILL);  // its group, if it leads one
      kill(pid, SIGKILL);
    }
    for (const pid_t pid : left)
      waitpid(pid, nullptr, 0);
  }
}

// Keeps what the child prints: the first kMaxOutput bytes as they come, then only the protocol's
// lines (see kMaxOutput).
class OutputKeeper {
 public:
  explicit OutputKeeper(std::string& output) : output_(output) {}
  void add(const char* data, std::size_t size) {
    std::string_view in(data, size);
    if (!capped_) {
      const std::size_t take = std::min(in.size(), kMaxOutput - output_.size());
      output_.append(in.substr(0, take));
      in.remove_prefix(take);
      if (output_.size() < kMaxOutput) return;
      // At the cap: the line cut there goes on in the lines kept after it.
      capped_ = true;
      const auto last = output_.rfind('\n');
      line_ = output_.substr(last == std::string::npos ? 0 : last + 1);
      output_.resize(output_.size() - line_.size());
    }
    for (const char c : in) {
      if (c != '\n') {
        line_ += c;
        // A line longer than any event keeps only its end, where an event printed after text
        // without a newline would be.
        if (line_.size() >= 2 * kMaxLine) line_.erase(0, line_.size() - kMaxLine);
        continue;
      }
      keep_event();
      line_.clear();
    }
  }
  void finish() { keep_event(); }

 private:
  // The current line from its tag on, when it holds one.
  void keep_event() {
    const auto at = line_.find("@clothlab\t");
    if (at == std::string::npos || events_ + line_.size() - at >= kMaxEvents) return;
    output_.append(line_, at).append("\n");
    events_ += line_.size() - at + 1;
  }

  static constexpr std::size_t kMaxLine = 256 << 10;  // longer than any event line
  std::string& output_;
  bool capped_ = false;  // kMaxOutput reached: only the protocol's lines are kept from here
  std::string line_;
  std::size_t events_ = 0;
};

}  // namespace

void adopt_orphans() {
  prctl(PR_SET_CHILD_SUBREAPER, 1);
}

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

ProcessResult run_process(const std::vector<std::string>& args, double timeout,
                          const ProcessLimits& limits) {
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
    auto limit = [](int resource, rlim_t value) {
      if (value == 0) return;
      const rlimit r{value, value};
      setrlimit(resource, &r);
    };
    limit(RLIMIT_AS, limits.memory_bytes);
    limit(RLIMIT_CPU, static_cast<rlim_t>(std::ceil(limits.cpu_seconds)));
    limit(RLIMIT_FSIZE, limits.file_bytes);
    const rlimit no_core{0, 0};  // a crash leaves no core file in the grader's folder
    setrlimit(RLIMIT_CORE, &no_core);
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
  OutputKeeper keeper(result.output);
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
    keeper.add(buffer, static_cast<std::size_t>(got));
  }
  keeper.finish();
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
  // Nothing the child started outlives it: what is left of its group, and what left the group.
  kill(-pid, SIGKILL);
  end_orphans();
  return result;
}

}  // namespace clothlab::app
