// cases.hpp: what a grading case is, and how its verdict is reached.
//
// doctest runs all cases in one process, so one crash or endless loop would lose every grade
// after it. The grader therefore lists the cases of a grading binary, then runs each in its own
// process group with a real timeout, and reads the line protocol the binary's "clothlab"
// reporter writes to a pipe of its own (protocol.hpp; tests/grade/harness/grade_main.cpp describes
// it).
//
// The grading binary (grade-cases) holds the tests but not the exercise kernels: it calls them in
// a kernels process (grade-kernels-reference, -stubs, or a submission's), which only computes and
// cannot reach the pipe the verdicts go through (tests/grade/harness/kernel_wire.hpp). A
// submission's kernels run in a sandbox.
#pragma once

#include <string>
#include <vector>

namespace clothlab::app::grading {

// One grading test case: what the listing says, then how its run went.
struct Case {
  // As the binary lists them; the name stays as it is, to select the case by, and a report shows
  // it with one_line (text.hpp), as file and exercise already are.
  std::string suite, name, file, exercise;
  int line = 0;
  int points = 0;
  std::string visibility = "visible";  // Gradescope: visible, hidden, after_due_date, ...
  bool hidden_test = false;            // from tests/grade-hidden/: graded only with --hidden

  bool done = false;
  bool passed = false;
  bool not_started = false;   // failed on the stub's NotImplemented
  bool not_compiled = false;  // the submission it was graded on did not compile
  bool broken_file = false;   // ...because its own exercise file did not (the student's loop)
  std::string status = "not run";
  std::string message;    // the first failure, with its INFO/CAPTURE hints
  std::string diagnosis;  // that failure in one line: its hint (hint_of), or what went wrong
  std::string output;     // what the case printed itself
  double seconds = 0;
};

// What grades: a grading binary, and the kernels program it calls (empty for a binary that has
// its own code, like the grader's self-test), in the sandbox when there is one.
struct Grader {
  std::string binary;
  std::string kernels;
  std::vector<std::string> sandbox;  // the command the kernels run in, or empty

  // The environment that tells the binary how to start the kernels (kernel_client.cpp).
  std::vector<std::string> environment() const {
    if (kernels.empty()) return {};
    std::string command;
    for (const std::string& arg : sandbox)
      command += arg + '\x1f';
    return {"CLOTHLAB_KERNELS=" + command + kernels};
  }
  // How to run a case by hand (without the sandbox).
  std::string command() const {
    return (kernels.empty() ? "" : "CLOTHLAB_KERNELS=" + kernels + " ") + binary;
  }
};

// The cases of a grading binary, in the order of their exercises (ex01.2 before ex01.10).
// Fails (kExitBadInput) when the binary cannot list them, lists none, or gives a case an unknown
// visibility.
std::vector<Case> list_cases(const std::string& binary);

// Runs case c alone, in a process of its own cut off after `timeout` seconds, and judges it:
// c.status, c.message, c.diagnosis and the flags say how it went.
void run_case(const Grader& grader, Case& c, double timeout);

}  // namespace clothlab::app::grading
