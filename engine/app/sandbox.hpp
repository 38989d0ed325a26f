// sandbox.hpp: how a submission's code is confined while it is compiled and while its kernels run
// (README, "The threat model").
//
// Two layers, each where the machine allows it:
// - a user: when the grader runs as root, the submission's processes run as the user nobody
//   (util-linux's setpriv), so they cannot write the grader's files, signal or read its
//   processes, and the limit on threads holds for them (Linux does not hold root to it);
// - a sandbox: bubblewrap gives them a new root that holds the system's programs and libraries
//   (read-only), /dev (read-only but for a small /dev/shm), /proc, a small empty /tmp and only the
//   files they need; no network, no other process to see, a session of their own, and every
//   process ends with them.
// And, in every mode, the kernels start through grade-confine (confine_main.cpp): an environment
// of PATH, LANG=C and HOME alone, and a filter that lets them start threads but no process (and,
// without a sandbox, write no file), so that the memory of a case is bounded as a whole: its
// address space (RLIMIT_AS) and the sandbox's two small folders in memory (kTmpBytes each).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace clothlab::app {

struct Confinement {
  std::vector<std::string> user;  // the command that switches to nobody, or empty
  std::string bwrap;              // bubblewrap, when it works here (for `user`), or empty

  // The command to put before the kernels program `program` (which reads and writes only its
  // pipes): the user, the sandbox holding `program` and `launcher` (grade-confine) alone, and the
  // launcher.
  std::vector<std::string> kernels(const std::string& launcher, const std::string& program) const;
  // The command to put before a build that reads `inputs` (files or folders) and writes in
  // `work` alone, with an environment of PATH, LANG=C and HOME=work.
  std::vector<std::string> build(const std::vector<std::string>& inputs,
                                 const std::string& work) const;
};

// The size of each of the sandbox's folders in memory, /tmp and /dev/shm [bytes].
constexpr std::size_t kTmpBytes = std::size_t{64} << 20;

// What confines a submission here. `mode`: "on" (a sandbox or nothing: an empty bwrap then means
// the caller must refuse to grade), "auto" (a sandbox where bubblewrap works), "off" (neither a
// sandbox nor another user). The user nobody is taken only when it can read every path in
// `reachable` (a build folder under a folder only root may enter would stop it); `warnings` gets
// why not.
Confinement confine(const std::string& mode, const std::vector<std::string>& reachable,
                    std::string& warnings);

// Gives `dir` and everything in it to the user that `c` runs as (nothing to do when that is
// the grader's own), so that a confined build can write there.
void hand_over(const Confinement& c, const std::string& dir);

// Takes every permission from group and others on what holds the hidden tests: their sources
// (tests/grade-hidden/ of `source`), and in the build folder `build` the grading binary, the
// objects of the grading tests and the lists of their names (ctest's).
void keep_hidden_tests_to_owner(const std::string& build, const std::string& source);

}  // namespace clothlab::app
