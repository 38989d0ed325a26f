// sandbox.hpp: how a submission's code is confined while it is compiled and while its kernels run
// (README, "The threat model").
//
// Two layers, each where the machine allows it:
// - a user: when the grader runs as root, the submission's processes run as the user nobody
//   (util-linux's setpriv), so they cannot write the grader's files, signal or read its
//   processes, and the limit on processes holds for them (Linux does not hold root to it);
// - a sandbox: bubblewrap gives them a new root that holds the system's programs and libraries
//   (read-only), /dev, /proc, an empty /tmp and only the files they need; no network, no other
//   process to see, a session of their own, and every process ends with them.
#pragma once

#include <string>
#include <vector>

namespace clothlab::app {

struct Confinement {
  std::vector<std::string> user;  // the command that switches to nobody, or empty
  std::string bwrap;              // bubblewrap, when it works here (for `user`), or empty

  // The command to put before the kernels program `program` (which reads and writes only its
  // pipes): the user, the sandbox holding `program` alone, and a limit of kMaxProcesses
  // processes.
  std::vector<std::string> kernels(const std::string& program) const;
  // The command to put before a build that reads `inputs` (files or folders) and writes in
  // `work` alone.
  std::vector<std::string> build(const std::vector<std::string>& inputs,
                                 const std::string& work) const;
};

constexpr int kMaxProcesses = 64;

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

}  // namespace clothlab::app
