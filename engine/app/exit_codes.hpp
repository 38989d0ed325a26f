// exit_codes.hpp: what clothlab's exit status means, the same for every command.
#pragma once

namespace clothlab::app {

enum ExitCode : int {
  kExitOk = 0,
  // The command ran and what it was asked to require was not met (grade --require-full,
  // --require-zero), or an error nobody foresaw.
  kExitFailed = 1,
  // What it was given is wrong (a scene file, an option, a path), or what it needs is missing (a
  // program not built): it says what, and nothing was done.
  kExitBadInput = 2,
  // run: the simulation stopped (the guard); the frames up to then are written.
  kExitBlewUp = 3,
  // An exercise kernel is still a stub (run, bench): it names the exercise.
  kExitNotDone = 4,
  // Ctrl-C or a TERM: the results of the work done so far are written.
  kExitInterrupted = 130,
};

}  // namespace clothlab::app
