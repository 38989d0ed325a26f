// sandbox.cpp: see sandbox.hpp.
#include "app/sandbox.hpp"

#include <unistd.h>

#include <fmt/core.h>

#include <filesystem>
#include <system_error>

#include "app/process.hpp"

namespace clothlab::app {
namespace {

namespace fs = std::filesystem;

constexpr uid_t kNobody = 65534;

// True when args runs and exits 0 within 10 s.
bool runs(const std::vector<std::string>& args) {
  const ProcessResult probe = run_process(args, 10);
  return !probe.timed_out && probe.signal == 0 && probe.exit_code == 0;
}

std::vector<std::string> joined(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// The start of every sandbox: the system, read-only, and nothing else of the machine.
std::vector<std::string> sandbox_root(const std::string& bwrap) {
  std::vector<std::string> args{bwrap, "--unshare-all", "--die-with-parent", "--new-session"};
  const auto add = [&](std::initializer_list<std::string> more) { args.insert(args.end(), more); };
  add({"--ro-bind", "/usr", "/usr"});
  for (const char* dir : {"/lib", "/lib64", "/bin"})
    add({"--ro-bind-try", dir, dir});  // links into /usr on most systems
  add({"--ro-bind", "/etc", "/etc"});
  add({"--dev", "/dev"});
  add({"--proc", "/proc"});
  add({"--tmpfs", "/tmp"});
  return args;
}

}  // namespace

std::vector<std::string> Confinement::kernels(const std::string& program) const {
  std::vector<std::string> args = user;
  if (!bwrap.empty()) {
    args = joined(args, sandbox_root(bwrap));
    args = joined(args, {"--ro-bind", program, program, "--chdir", "/tmp", "--"});
  }
  // The kernel counts processes per user; in the sandbox's user namespace, the sandbox's own.
  if (access("/usr/bin/prlimit", X_OK) == 0)
    args = joined(args, {"/usr/bin/prlimit", fmt::format("--nproc={}", kMaxProcesses)});
  return args;
}

std::vector<std::string> Confinement::build(const std::vector<std::string>& inputs,
                                            const std::string& work) const {
  std::vector<std::string> args = user;
  if (bwrap.empty()) return args;
  args = joined(args, sandbox_root(bwrap));
  for (const std::string& input : inputs)
    args = joined(args, {"--ro-bind", input, input});
  return joined(args, {"--bind", work, work, "--chdir", work, "--"});
}

Confinement confine(const std::string& mode, const std::vector<std::string>& reachable,
                    std::string& warnings) {
  Confinement c;
  if (mode == "off") return c;
  const std::vector<std::string> setpriv{"/usr/bin/setpriv", fmt::format("--reuid={}", kNobody),
                                         fmt::format("--regid={}", kNobody), "--clear-groups"};
  if (geteuid() == 0 && access(setpriv[0].c_str(), X_OK) == 0) {
    c.user = setpriv;
    for (const std::string& path : reachable) {
      if (runs(joined(setpriv, {"/usr/bin/test", "-r", path}))) continue;
      warnings += fmt::format(
          "the user nobody cannot read {} (a folder above it is closed to other users): the "
          "submission's code runs as root\n",
          path);
      c.user.clear();
      break;
    }
  }
  for (const char* path : {"/usr/bin/bwrap", "/usr/local/bin/bwrap", "/bin/bwrap"}) {
    if (access(path, X_OK) != 0) continue;
    if (runs(joined(c.user, {path, "--unshare-all", "--die-with-parent", "--ro-bind", "/", "/",
                             "/bin/true"}))) {
      c.bwrap = path;
      break;
    }
  }
  return c;
}

void hand_over(const Confinement& c, const std::string& dir) {
  if (c.user.empty()) return;
  std::error_code ec;
  [[maybe_unused]] int ignored = lchown(dir.c_str(), kNobody, kNobody);
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec))
    ignored = lchown(it->path().c_str(), kNobody, kNobody);
}

}  // namespace clothlab::app
