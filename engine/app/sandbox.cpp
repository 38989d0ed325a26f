// sandbox.cpp: see sandbox.hpp.
#include "app/sandbox.hpp"

#include <sys/stat.h>
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

// The start of every sandbox: the system, read-only, and nothing else of the machine. Its only
// writable places are two folders in memory of kTmpBytes each (/dev is read-only, but for
// /dev/shm), and no nested namespace can mount more.
std::vector<std::string> sandbox_root(const std::string& bwrap) {
  std::vector<std::string> args{
      bwrap,          "--unshare-all", "--unshare-user", "--disable-userns", "--die-with-parent",
      "--new-session"};
  const auto add = [&](std::initializer_list<std::string> more) { args.insert(args.end(), more); };
  add({"--ro-bind", "/usr", "/usr"});
  for (const char* dir : {"/lib", "/lib64", "/bin"})
    add({"--ro-bind-try", dir, dir});  // links into /usr on most systems
  add({"--ro-bind", "/etc", "/etc"});
  add({"--dev", "/dev"});
  const std::string size = std::to_string(kTmpBytes);
  add({"--size", size, "--tmpfs", "/dev/shm", "--remount-ro", "/dev"});
  add({"--proc", "/proc"});
  add({"--size", size, "--tmpfs", "/tmp"});
  return args;
}

}  // namespace

std::vector<std::string> Confinement::kernels(const std::string& launcher,
                                              const std::string& program) const {
  std::vector<std::string> args = user;
  if (!bwrap.empty()) {
    args = joined(args, sandbox_root(bwrap));
    args = joined(args, {"--ro-bind", launcher, launcher, "--ro-bind", program, program, "--chdir",
                         "/tmp", "--"});
  }
  // Without a sandbox, the machine's folders are the kernels' to write in: they may write none.
  if (bwrap.empty()) return joined(args, {launcher, "--no-writes", "/tmp", program});
  return joined(args, {launcher, "/tmp", program});
}

std::vector<std::string> Confinement::build(const std::vector<std::string>& inputs,
                                            const std::string& work) const {
  std::vector<std::string> args = user;
  if (!bwrap.empty()) {
    args = joined(args, sandbox_root(bwrap));
    for (const std::string& input : inputs)
      args = joined(args, {"--ro-bind", input, input});
    args = joined(args, {"--bind", work, work, "--chdir", work, "--"});
  }
  // Nothing of the grader's environment reaches the compiler (CPATH, say, would add folders to
  // look for headers in).
  return joined(args, {"/usr/bin/env", "-i", "PATH=/usr/bin:/bin", "LANG=C", "HOME=" + work});
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

void keep_hidden_tests_to_owner(const std::string& build, const std::string& source) {
  std::vector<fs::path> paths{fs::path(build) / "grade-cases",
                              fs::path(build) / "tests/grade/CMakeFiles/clothlab_grade_tests.dir",
                              fs::path(source) / "tests/grade-hidden"};
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(fs::path(build) / "tests/grade", ec)) {
    if (entry.path().filename().string().starts_with("grade-cases_")) paths.push_back(entry.path());
  }
  for (const fs::path& path : paths) {
    struct stat s {};
    // A symbolic link is left alone: chmod would change what it points to.
    if (lstat(path.c_str(), &s) != 0 || S_ISLNK(s.st_mode)) continue;
    chmod(path.c_str(), s.st_mode & 0700);
  }
}

}  // namespace clothlab::app
