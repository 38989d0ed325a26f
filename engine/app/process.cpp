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

// Keeps at most `cap` bytes of what comes through a pipe, and counts what it leaves out.
class Capped {
 public:
  Capped(std::string& text, std::size_t cap) : text_(text), cap_(cap) {}
  void add(const char* data, std::size_t size) {
    const std::size_t take = std::min(size, cap_ - text_.size());
    text_.append(data, take);
    dropped_ += size - take;
  }
  std::size_t dropped() const { return dropped_; }

 private:
  std::string& text_;
  std::size_t cap_;
  std::size_t dropped_ = 0;
};

// The environment of the child: this one's, with `set` ("NAME=value") in place of the same
// names, and no CLOTHLAB_EVENTS_FD unless `set` gives it.
std::vector<std::string> environment(const std::vector<std::string>& set) {
  std::vector<std::string> env = set;
  auto name_of = [](std::string_view entry) { return entry.substr(0, entry.find('=')); };
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string_view entry(*e);
    const std::string_view name = name_of(entry);
    if (name == "CLOTHLAB_EVENTS_FD") continue;
    if (std::any_of(set.begin(), set.end(),
                    [&](const std::string& s) { return name_of(s) == name; }))
      continue;
    env.emplace_back(entry);
  }
  return env;
}

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
                          const ProcessLimits& limits, const std::vector<std::string>& env,
                          bool events) {
  // Built before fork(): the child may only make async-signal-safe calls. A program named without
  // a folder is looked for on the PATH.
  std::vector<std::string> program_args = args;
  if (!program_args.empty() && program_args[0].find('/') == std::string::npos) {
    const char* path = std::getenv("PATH");
    std::string_view dirs = path != nullptr ? path : "/usr/bin:/bin";
    for (std::size_t at = 0; at <= dirs.size();) {
      const std::size_t end = std::min(dirs.find(':', at), dirs.size());
      const std::string candidate = std::string(dirs.substr(at, end - at)) + "/" + program_args[0];
      if (end > at && access(candidate.c_str(), X_OK) == 0) {
        program_args[0] = candidate;
        break;
      }
      at = end + 1;
    }
  }
  std::vector<char*> argv;
  for (auto& a : program_args)
    argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_entries = env;
  if (events) env_entries.push_back("CLOTHLAB_EVENTS_FD=" + std::to_string(kEventsFd));
  env_entries = environment(env_entries);
  std::vector<char*> envp;
  for (auto& e : env_entries)
    envp.push_back(e.data());
  envp.push_back(nullptr);

  int fds[2];
  int event_fds[2] = {-1, -1};
  if (pipe2(fds, O_CLOEXEC) != 0 || (events && pipe2(event_fds, O_CLOEXEC) != 0))
    throw std::system_error(errno, std::generic_category(), "pipe");
  const pid_t pid = fork();
  if (pid < 0) throw std::system_error(errno, std::generic_category(), "fork");
  if (pid == 0) {
    setpgid(0, 0);  // its own process group: a timeout kills whatever the case started too
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // and it ends if this process dies (Ctrl-C, say)
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
    if (events) {
      // dup2 onto itself would leave it close-on-exec.
      if (event_fds[1] == kEventsFd)
        fcntl(kEventsFd, F_SETFD, 0);
      else
        dup2(event_fds[1], kEventsFd);
    }
    execve(argv[0], argv.data(), envp.data());
    const char message[] = "clothlab grade: cannot execute the program\n";
    [[maybe_unused]] auto ignored = write(STDERR_FILENO, message, sizeof message - 1);
    _exit(127);
  }
  setpgid(pid, pid);  // also here, so the kill below cannot race the child's own call
  close(fds[1]);
  if (events) close(event_fds[1]);

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

  // Read until end of file on both pipes (the case and anything it started closed them) or the
  // deadline. Once the child has ended, whatever it left behind is ended too, and what is still in
  // the pipes is read for at most kDrainMs: a process that kept them open cannot hold the grader
  // to the deadline.
  constexpr long kDrainMs = 200;
  char buffer[4096];
  Capped output(result.output, kMaxOutput);
  Capped event_lines(result.events, kMaxEvents);
  pollfd p[2] = {{fds[0], POLLIN, 0}, {event_fds[0], POLLIN, 0}};  // fd -1: ignored by poll
  int status = 0;
  bool ended = false;
  auto drain_until = Clock::now();
  while (p[0].fd >= 0 || p[1].fd >= 0) {
    if (g_interrupted) {
      stop(result.interrupted);
      break;
    }
    if (!ended && waitpid(pid, &status, WNOHANG) == pid) {
      ended = true;
      kill(-pid, SIGKILL);
      end_orphans();
      drain_until = Clock::now() + std::chrono::milliseconds(kDrainMs);
    }
    if (ended && Clock::now() >= drain_until) break;
    const long left = time_left_ms();
    if (left == 0 && !ended) {
      stop(result.timed_out);
      break;
    }
    const int ready = poll(p, 2, static_cast<int>(std::min<long>(std::max(left, 1L), 20)));
    if (ready <= 0) continue;  // a slice passed, or EINTR: check the child, deadline and flag
    for (int k = 0; k < 2; ++k) {
      if (p[k].fd < 0 || p[k].revents == 0) continue;
      const ssize_t got = read(p[k].fd, buffer, sizeof buffer);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) {
        p[k].fd = -1;
        continue;
      }
      (k == 0 ? output : event_lines).add(buffer, static_cast<std::size_t>(got));
    }
  }
  if (output.dropped() > 0)
    result.output += "\n[... " + std::to_string(output.dropped()) + " more bytes not kept]\n";
  close(fds[0]);
  if (events) close(event_fds[0]);

  // The pipes can close before the process ends: wait for it, still under the deadline.
  while (!ended) {
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
