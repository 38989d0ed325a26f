// cases.cpp: a case's verdict, from how its process ended and what its reporter said; listing the
// cases of a grading binary and running one (cases.hpp).
#include "app/grade/cases.hpp"
#include "app/exit_codes.hpp"
#include "app/grade/exercises.hpp"
#include "app/grade/kernels_crash.hpp"
#include "app/grade/protocol.hpp"
#include "app/grade/text.hpp"
#include "app/process.hpp"

#include <signal.h>

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstddef>
#include <cstdlib>
#include <iostream>
#include <iterator>
#include <string_view>
#include <utility>

namespace clothlab::app::grading {
namespace {

using Clock = std::chrono::steady_clock;

// The signals a test process typically dies of, and what usually causes each.
struct SignalInfo {
  int number;
  const char* name;
  const char* hint;
};
constexpr SignalInfo kSignals[] = {
    {SIGSEGV, "SIGSEGV", "memory the program does not own: an index out of range?"},
    {SIGBUS, "SIGBUS", "memory the program does not own: an index out of range?"},
    {SIGFPE, "SIGFPE", "an integer division by zero?"},
    {SIGABRT, "SIGABRT", "a failed assert(), or an exception thrown where none may be?"},
    {SIGILL, "SIGILL", ""},
    {SIGKILL, "SIGKILL", "killed from outside: out of memory?"},
    {SIGTERM, "SIGTERM", "stopped from outside"},
};

SignalInfo signal_info(int sig) {
  for (const SignalInfo& s : kSignals) {
    if (s.number == sig) return s;
  }
  return {sig, "another signal", ""};
}

// The signal a case died of. doctest reports a crash, then re-raises the signal; under a
// sanitizer, the sanitizer's handler may exit with a code instead, so the report alone counts too.
SignalInfo crash_signal(int sig, const std::string& reported) {
  if (sig != 0) return signal_info(sig);
  for (const SignalInfo& s : kSignals) {
    if (reported.starts_with(s.name)) return s;
  }
  return {0, "another signal", ""};
}

// --- Messages -----------------------------------------------------------------------------------

// The exercise a stub's NotImplemented names ("exercise ex01.2 is not implemented yet: ..."),
// or "" when the text is something else.
std::string not_implemented_in(const std::string& text) {
  const auto end = text.find(" is not implemented yet");
  const auto begin = text.rfind("exercise ", end);
  if (end == std::string::npos || begin == std::string::npos) return "";
  return text.substr(begin + 9, end - begin - 9);
}

// fail FILE LINE MACRO EXPRESSION VALUES CONTEXT...
std::string describe_failure(const Fields& e) {
  std::string s = fmt::format("{}:{}: ", relative_path(e[1]), e[2]);
  if (e[4].empty()) {
    s += e[5];  // FAIL("message")
  } else {
    s += fmt::format("{}( {} ) failed", e[3], e[4]);
    // A bare "false" says nothing the expression does not; the INFO lines below say more.
    if (e[5] != "false" && e[5] != e[4]) s += "\n  values: " + e[5];
  }
  for (std::size_t i = 6; i < e.size(); ++i)
    s += "\n  " + e[i];
  return s;
}

// exception throw|crash TEXT CONTEXT...
std::string describe_exception(const Fields& e) {
  std::string s = (e[1] == "crash" ? "the process crashed: " : "threw an exception: ") + e[2];
  for (std::size_t i = 3; i < e.size(); ++i)
    s += "\n  " + e[i];
  return s;
}

// A failed check in one line: its teaching hint. The contexts run from the outermost INFO (the
// setup, "a 3 x 3 grid") in; the innermost that is neither a CAPTURE ("y := 0.5") nor the
// check's own "got ..., expected ..." is the hint. Failing that, the check itself.
std::string hint_of(const Fields& e) {
  for (std::size_t i = e.size(); i-- > 6;) {
    if (e[i].find(" := ") == std::string::npos && !e[i].starts_with("got ")) return e[i];
  }
  if (e.size() > 6) return e.back();
  return e[4].empty() ? e[5] : fmt::format("{}( {} ) failed", e[3], e[4]);
}

// The signal in the text of KernelsEnded (kernel_client.cpp) when the kernels' process died of
// one: "crashed: signal 11 (...)"; 0 otherwise.
int kernels_signal(const std::string& text) {
  if (!text.starts_with(kKernelsCrashed)) return 0;
  return std::atoi(text.c_str() + kKernelsCrashed.size());
}

// Decides a case's status from how its process ended and what its reporter said.
void judge(Case& c, const ProcessResult& run, const Grader& grader, double timeout) {
  std::vector<Fields> events = parse_events(run.events);
  c.output = run.output;

  int starts = 0;
  bool ended = false;
  bool reported_pass = false;
  std::string first_failure;
  std::string first_hint;     // the first failure in one line (hint_of), or the exception's text
  std::string missing;        // the exercise a NotImplemented named
  std::string crash;          // what doctest said when it caught a crash signal
  int kernels_sig = 0;        // the signal the kernels' process died of, when it did
  std::string kernels_crash;  // and what the grading binary said of it
  for (Fields& e : events) {
    // The fewest fields each event has, so that a line cut short cannot crash the grader.
    const std::size_t fields = e[0] == "fail" ? 6 : e[0] == "note" ? 4 : 3;
    if (e.size() < fields) e.resize(fields);
    // Each field is data (a file name, an expression, a value, a hint, an exception's text): shown
    // on one line, within the lines the grader lays out.
    for (std::size_t i = 1; i < e.size(); ++i)
      e[i] = one_line(e[i]);
    if (e[0] == "start") {
      ++starts;
    } else if (e[0] == "fail" || e[0] == "exception") {
      const bool is_fail = e[0] == "fail";
      if (first_failure.empty()) {
        first_failure = is_fail ? describe_failure(e) : describe_exception(e);
        first_hint = is_fail ? hint_of(e) : e[2];
      }
      if (missing.empty()) missing = not_implemented_in(is_fail ? e[5] : e[2]);
      if (!is_fail && e[1] == "crash") crash = e[2];
      if (!is_fail && kernels_sig == 0 && (kernels_sig = kernels_signal(e[2])) != 0)
        kernels_crash = e[2];
    } else if (e[0] == "note") {
      c.output += fmt::format("note: {}\n", e[3]);
    } else if (e[0] == "end") {
      ended = true;
      reported_pass = e[1] == "passed";
    }
  }

  c.done = true;
  c.message = first_failure;
  if (run.interrupted) {
    c.done = false;
    c.status = "not run (interrupted)";
  } else if (run.timed_out) {
    c.status = fmt::format("timed out after {:g} s", timeout);
    c.message = fmt::format("the case did not finish within {:g} s: an endless loop?", timeout) +
                (first_failure.empty() ? "" : "\nbefore that, " + first_failure);
  } else if (run.signal != 0 || !crash.empty() || kernels_sig != 0) {
    const SignalInfo sig = kernels_sig != 0 && run.signal == 0 ? signal_info(kernels_sig)
                                                               : crash_signal(run.signal, crash);
    c.status = fmt::format("crashed: {}", sig.name);
    if (kernels_sig != 0 && run.signal == 0 && crash.empty())
      c.message =
          fmt::format("the exercise's code was killed by signal {} ({}){}", kernels_sig, sig.name,
                      kernels_crash.substr(kernels_crash.find(' ', kKernelsCrashed.size())));
    if (c.message.empty())
      c.message = fmt::format("the process was killed by signal {}", run.signal);
    if (*sig.hint != '\0') c.message += fmt::format("\n{}", sig.hint);
  } else if (starts == 0) {
    c.status = "failed: no test case ran";
    c.message = "the binary ran no case named \"" + one_line(c.name) +
                "\" (it was listed, so this is never a pass)";
  } else if (starts > 1) {
    c.status = fmt::format("failed: the name matched {} cases", starts);
    c.message = "rename the case: its name must select it alone";
  } else if (!ended) {
    c.status = fmt::format("exited with code {} before reporting a result", run.exit_code);
    if (c.message.empty()) c.message = c.status + " (a call to exit()?)";
  } else if (reported_pass && run.exit_code == 0) {
    c.passed = true;
    c.status = "passed";
  } else if (!missing.empty() && missing == c.exercise) {
    c.not_started = true;
    c.status = "not started";
  } else {
    c.status = "failed";
    if (!missing.empty())
      c.message = "this test also needs " + missing + ", which is not started yet";
    if (c.message.empty())
      c.message = fmt::format("the test program exited with code {}", run.exit_code);
  }
  if (run.timed_out || run.signal != 0 || !crash.empty() || kernels_sig != 0) {
    c.message += fmt::format("\nto run this case alone: {} --test-case=\"{}\"", grader.command(),
                             one_line(c.name));
  }
  // One line: the first hint when the status alone does not say what went wrong.
  const std::string line = (c.passed || c.not_started) ? ""
                           : c.status == "failed" && missing.empty() && !first_hint.empty()
                               ? first_hint
                               : c.message;
  c.diagnosis = line.substr(0, line.find('\n'));
  if (c.diagnosis.size() > 160) c.diagnosis = c.diagnosis.substr(0, 157) + "...";
  c.message = printable(c.message);
  c.diagnosis = printable(c.diagnosis);
  c.output = printable(c.output);
}

}  // namespace

// --- Listing and running cases ----------------------------------------------------------------

std::vector<Case> list_cases(const std::string& binary) {
  const ProcessResult run =
      run_process({binary, "--list-test-cases", "--reporters=clothlab"}, 60, {}, {}, true);
  std::vector<Fields> events = parse_events(run.events);
  if (run.timed_out || run.signal != 0 || run.exit_code != 0) {
    fail(kExitBadInput, fmt::format("listing the cases of {} failed:\n{}", binary, run.output));
  }
  std::vector<Case> cases;
  for (Fields& e : events) {
    if (e[0] != "case") continue;
    e.resize(7);
    Case c;
    c.suite = e[1];
    c.name = e[2];
    // The name stays as it is, to select the case by; a report shows it with one_line.
    c.file = one_line(relative_path(e[3]));
    c.line = std::atoi(e[4].c_str());
    c.exercise = one_line(exercise_of(c.name, c.suite));
    if (e[5].empty()) {
      std::cerr << fmt::format(
          "clothlab grade: warning: {}:{}: case \"{}\" has no POINTS(n): it counts 0 points\n",
          c.file, c.line, one_line(c.name));
    }
    c.points = std::atoi(e[5].c_str());
    // A hidden test (tests/grade-hidden/) shows on Gradescope once the due date has passed,
    // unless it says otherwise with POINTS_VISIBILITY.
    const bool hidden_file = c.file.find("grade-hidden/") != std::string::npos;
    c.hidden_test = hidden_file;
    c.visibility = !e[6].empty() ? e[6] : hidden_file ? "after_due_date" : "visible";
    constexpr std::string_view kVisibilities[] = {"visible", "hidden", "after_due_date",
                                                  "after_published"};
    if (std::find(std::begin(kVisibilities), std::end(kVisibilities), c.visibility) ==
        std::end(kVisibilities)) {
      fail(kExitBadInput,
           fmt::format("{}:{}: case \"{}\" has visibility \"{}\"; expected visible, hidden, "
                       "after_due_date or after_published",
                       c.file, c.line, one_line(c.name), one_line(c.visibility)));
    }
    cases.push_back(c);
  }
  if (cases.empty())
    fail(kExitBadInput, binary + " lists no test cases (was it built with grade_main.cpp?)");
  // doctest lists by file, and a hidden file may come first: order by exercise (ex01.2 before
  // ex01.10), keeping each exercise's cases in their order.
  auto key = [](const Case& c) {
    if (!is_exercise_id(c.exercise, true)) return std::pair<int, int>(1 << 30, 0);
    const auto dot = c.exercise.find('.');
    const int part = dot == std::string::npos ? 0 : std::atoi(c.exercise.c_str() + dot + 1);
    return std::pair<int, int>(std::atoi(c.exercise.c_str() + 2), part);
  };
  std::stable_sort(cases.begin(), cases.end(),
                   [&](const Case& a, const Case& b) { return key(a) < key(b); });
  return cases;
}

void run_case(const Grader& grader, Case& c, double timeout) {
  if (c.name.find(',') != std::string::npos) {
    c.done = true;
    c.status = "failed: the name contains a comma";
    c.message = "doctest splits --test-case filters at commas: rename the case";
    return;
  }
  // doctest matches names with wildcards it cannot escape; '?' still matches '*' or '?' itself,
  // and judge() fails the case if that ever selects more than one case.
  std::string filter;
  for (char ch : c.name)
    filter += (ch == '*' || ch == '?') ? std::string("?")
              : ch == '\\'             ? std::string("\\\\")
                                       : std::string(1, ch);
  // A case may not take the machine: its memory, processor time and files are bounded, for every
  // process it starts. (AddressSanitizer reserves terabytes of address space, so a sanitized
  // grader leaves the memory bound to the sanitizer.)
  ProcessLimits limits;
#ifndef __SANITIZE_ADDRESS__
  limits.memory_bytes = std::size_t{4} << 30;
#endif
  limits.cpu_seconds = timeout + 1;
  limits.file_bytes = std::size_t{64} << 20;
  const auto start = Clock::now();
  const ProcessResult run =
      run_process({grader.binary, "--reporters=clothlab", "--test-case=" + filter,
                   "--case-sensitive=true", "--no-breaks=true"},
                  timeout, limits, grader.environment(), true);
  c.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  judge(c, run, grader, timeout);
}

}  // namespace clothlab::app::grading
