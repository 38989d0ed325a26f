// grade.cpp: `clothlab grade`, the test grader.
//
// doctest runs all cases in one process, so one crash or endless loop would lose every grade
// after it. The grader therefore lists the cases of a grading binary, then runs each in its own
// process group with a real timeout, and reads the line protocol the binary's "clothlab"
// reporter writes to a pipe of its own (tests/grade/grade_main.cpp describes it).
//
// The grading binary (grade-cases) holds the tests but not the exercise kernels: it calls them in
// a kernels process (grade-kernels-reference, -stubs, or a submission's), which only computes and
// cannot reach the pipe the verdicts go through (tests/grade/kernel_wire.hpp). A submission's
// kernels run in a sandbox.
#include "app/grade.hpp"
#include "app/exit_codes.hpp"
#include "app/process.hpp"
#include "app/sandbox.hpp"
#include "app/submission.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/color.h>
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "io/json.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace clothlab::app {
namespace {

namespace fs = std::filesystem;
using namespace std::string_literals;
using Clock = std::chrono::steady_clock;
using Fields = std::vector<std::string>;

struct Options {
  std::string impl = "student";
  std::string exercise;  // "ex01" or "ex01.2"; empty for all
  bool list = false;
  double timeout = 10;  // per case [s]
  std::string results;  // Gradescope results.json
  std::string junit;
  bool require_full = false;
  bool require_zero = false;
  std::string binary;      // hidden: grade this doctest binary instead of grade-<impl>
  std::string submission;  // grade the exercise files in this folder
  std::string scratch;     // where a submission is built; default <dir of clothlab>/grade-scratch
  double build_timeout = 600;    // [s] for configuring, then for compiling, a submission
  std::string sandbox = "auto";  // a submission's cases in bubblewrap: auto, on or off
  bool autolab = false;          // end with Autolab's one-line JSON score summary
  std::string classroom;         // write a GitHub Classroom workflow here, and grade nothing
  bool hidden = false;           // also the hidden cases of tests/grade-hidden/ (instructors)
  std::string exercises;         // hidden: the student's exercise files; default exercises/
  int rounds = 0;                // watch: stop after this many gradings (0: never; for tests)
};

// One grading test case: what the listing says, then how its run went.
struct Case {
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

[[noreturn]] void fail(int exit_code, const std::string& message) {
  std::cout << std::flush;
  std::cerr << "clothlab grade: " << message << "\n";
  throw CLI::RuntimeError(exit_code);
}

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

// JSON and XML want valid UTF-8; a crashing case can print anything.
std::string valid_utf8(const std::string& in) {
  std::string out;
  for (std::size_t i = 0; i < in.size();) {
    const auto b = static_cast<unsigned char>(in[i]);
    const std::size_t n = b < 0x80           ? 1
                          : (b >> 5) == 0x6  ? 2
                          : (b >> 4) == 0xE  ? 3
                          : (b >> 3) == 0x1E ? 4
                                             : 0;
    bool ok = n > 0 && i + n <= in.size();
    for (std::size_t k = 1; ok && k < n; ++k)
      ok = (static_cast<unsigned char>(in[i + k]) >> 6) == 0x2;
    out += ok ? in.substr(i, n) : "?";
    i += ok ? n : 1;
  }
  return out;
}

// Text a submission wrote (its messages, its output, the compiler's quotes of its code) made
// safe for a terminal: valid UTF-8, with control characters shown in caret notation ("^[" for
// an escape), so that it cannot move the cursor, clear the screen or draw a fake result.
std::string printable(const std::string& text) {
  const std::string in = valid_utf8(text);
  std::string out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const auto b = static_cast<unsigned char>(in[i]);
    if (b == '\n' || b == '\t') {
      out += in[i];
    } else if (b < 0x20 || b == 0x7f) {
      out += '^';
      out += static_cast<char>(b == 0x7f ? '?' : b + 64);
    } else if (b == 0xc2 && i + 1 < in.size() && static_cast<unsigned char>(in[i + 1]) >= 0x80 &&
               static_cast<unsigned char>(in[i + 1]) <= 0x9f) {
      out += "^?";  // a C1 control (U+0080 to U+009F), which some terminals obey
      ++i;
    } else {
      out += in[i];
    }
  }
  return out;
}

// --- The line protocol ------------------------------------------------------------------------

constexpr std::string_view kTag = "@clothlab\t";

Fields split_event(std::string_view line) {
  Fields fields(1);
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '\t') {
      fields.emplace_back();
    } else if (c == '\\' && i + 1 < line.size()) {
      const char e = line[++i];
      fields.back() += e == 't' ? '\t' : e == 'n' ? '\n' : e == 'r' ? '\r' : e;
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

// The reporter's events, from the pipe only the grading binary writes (see grade_main.cpp).
std::vector<Fields> parse_events(const std::string& text) {
  std::vector<Fields> events;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    const std::string_view line(text.data() + begin, end - begin);
    if (line.starts_with(kTag)) events.push_back(split_event(line.substr(kTag.size())));
    begin = end + 1;
  }
  return events;
}

// --- Exercises, lessons and messages ---------------------------------------------------------

// An exercise ID: "ex01.3", or with lesson_only "ex01". (Parsed by hand: g++ 12 warns inside
// <regex> when built with the sanitizers.)
bool is_exercise_id(std::string_view id, bool lesson_only) {
  auto digits = [](std::string_view d) {
    return !d.empty() &&
           std::all_of(d.begin(), d.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (!id.starts_with("ex")) return false;
  const auto dot = id.find('.');
  if (dot == std::string_view::npos) return lesson_only && digits(id.substr(2));
  return digits(id.substr(2, dot - 2)) && digits(id.substr(dot + 1));
}

// "ex01.3 explicit Euler ..." -> "ex01.3"; a case without an ID counts under its suite.
std::string exercise_of(const std::string& name, const std::string& suite) {
  const std::string first_word = name.substr(0, name.find_first_of(" \t"));
  if (is_exercise_id(first_word, false)) return first_word;
  return suite.empty() ? "(no exercise)" : suite;
}

// "ex01.3" -> "1.3", as the lessons number their exercises.
std::string number_of(const std::string& exercise) {
  if (!is_exercise_id(exercise, true)) return exercise;
  const auto dot = exercise.find('.');
  const std::string part = dot == std::string::npos ? "" : exercise.substr(dot);
  return std::to_string(std::stoi(exercise.substr(2, dot - 2))) + part;
}

// "see lessons/01-particles-and-euler/README.md, Exercise ex01.3"
std::string lesson_hint(const std::string& exercise) {
  if (!is_exercise_id(exercise, true)) return "";
  const std::string prefix = exercise.substr(2, exercise.find('.') - 2) + "-";  // "01-"
  std::string lesson = "lessons/" + prefix + "*/README.md";
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(fs::path(CLOTHLAB_SOURCE_DIR) / "lessons", ec)) {
    const std::string folder = entry.path().filename().string();
    if (entry.is_directory() && folder.starts_with(prefix)) {
      lesson = "lessons/" + folder + "/README.md";
    }
  }
  return "see " + lesson + ", Exercise " + exercise;
}

std::string relative_path(const std::string& file) {
  const std::string root = std::string(CLOTHLAB_SOURCE_DIR) + "/";
  return file.starts_with(root) ? file.substr(root.size()) : file;
}

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
  constexpr std::string_view kCrashed = "crashed: signal ";
  if (!text.starts_with(kCrashed)) return 0;
  return std::atoi(text.c_str() + kCrashed.size());
}

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
      c.message = fmt::format("the exercise's code was killed by signal {} ({}){}", kernels_sig,
                              sig.name, kernels_crash.substr(kernels_crash.find(' ', 16)));
    if (c.message.empty())
      c.message = fmt::format("the process was killed by signal {}", run.signal);
    if (*sig.hint != '\0') c.message += fmt::format("\n{}", sig.hint);
  } else if (starts == 0) {
    c.status = "failed: no test case ran";
    c.message =
        "the binary ran no case named \"" + c.name + "\" (it was listed, so this is never a pass)";
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
    c.message +=
        fmt::format("\nto run this case alone: {} --test-case=\"{}\"", grader.command(), c.name);
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
    c.file = relative_path(e[3]);
    c.line = std::atoi(e[4].c_str());
    c.exercise = exercise_of(c.name, c.suite);
    if (e[5].empty()) {
      std::cerr << fmt::format(
          "clothlab grade: warning: {}:{}: case \"{}\" has no POINTS(n): it counts 0 points\n",
          c.file, c.line, c.name);
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
                       c.file, c.line, c.name, c.visibility));
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

// --- The sandbox --------------------------------------------------------------------------------

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

// --- Reports ------------------------------------------------------------------------------------

struct Exercise {
  std::string id;
  std::vector<const Case*> cases;
  int earned = 0, max = 0, passed = 0;
};

std::vector<Exercise> by_exercise(const std::vector<Case>& cases) {
  std::vector<Exercise> exercises;
  for (const Case& c : cases) {
    auto it = std::find_if(exercises.begin(), exercises.end(),
                           [&](const Exercise& x) { return x.id == c.exercise; });
    if (it == exercises.end()) it = exercises.insert(exercises.end(), Exercise{c.exercise, {}});
    it->cases.push_back(&c);
    it->max += c.points;
    if (c.passed) {
      it->earned += c.points;
      ++it->passed;
    }
  }
  return exercises;
}

std::string paint(bool colour, fmt::text_style style, const std::string& text) {
  return colour ? fmt::format(style, "{}", text) : text;
}

std::string indent(const std::string& text, const std::string& prefix) {
  std::string out = prefix;
  for (char ch : text)
    out += ch == '\n' ? "\n" + prefix : std::string(1, ch);
  return out;
}

std::string summary(const std::vector<Case>& cases, bool colour) {
  const auto red = fmt::fg(fmt::terminal_color::red);
  const auto green = fmt::fg(fmt::terminal_color::green);
  const auto yellow = fmt::fg(fmt::terminal_color::yellow);
  std::string s = fmt::format("{:<10} {:>9} {:>9}   {}\n", "Exercise", "Points", "Cases", "Status");
  int earned = 0, max = 0;
  std::vector<std::string> shown_errors;  // a file's compile error, once for its exercises
  for (const Exercise& x : by_exercise(cases)) {
    earned += x.earned;
    max += x.max;
    const Case* first = nullptr;
    bool all_not_started = true, all_run = true, not_compiled = false;
    for (const Case* c : x.cases) {
      if (!c->passed && first == nullptr) first = c;
      all_not_started = all_not_started && c->not_started;
      all_run = all_run && c->done;
      not_compiled = not_compiled || c->not_compiled;
    }
    std::string status;
    if (not_compiled)
      status = paint(colour, red, "not compiled");
    else if (first == nullptr)
      status = paint(colour, green, "done");
    else if (all_not_started)
      status = paint(colour, yellow, "not started: " + lesson_hint(x.id));
    else if (!all_run)
      status = paint(colour, yellow, "not run");
    else
      status = paint(colour, red, "failing");
    s += fmt::format("{:<10} {:>9} {:>9}   {}\n", x.id, fmt::format("{} / {}", x.earned, x.max),
                     fmt::format("{} / {}", x.passed, x.cases.size()), status);
    // A submission that does not build says why once, above the table; an exercise file of the
    // student's own that does not compile says it here, under the first of its exercises.
    if (not_compiled && first != nullptr && first->broken_file) {
      if (std::find(shown_errors.begin(), shown_errors.end(), first->message) ==
          shown_errors.end()) {
        shown_errors.push_back(first->message);
        s += indent(first->message, "    ") + "\n";
      }
    } else if (first != nullptr && !all_not_started && first->done && !not_compiled) {
      // The first failing case in full: what was computed, what was expected, where to read.
      s += fmt::format("    {}: {}\n", paint(colour, fmt::emphasis::bold, first->name),
                       paint(colour, red, first->status));
      if (!first->message.empty()) s += indent(first->message, "      ") + "\n";
      const std::string hint = lesson_hint(x.id);
      if (!hint.empty()) s += "      " + hint + "\n";
      // Every other one in a line: its name and what went wrong.
      for (const Case* c : x.cases) {
        if (c == first || c->passed || !c->done || c->not_compiled) continue;
        s += fmt::format("    {}: {}{}\n", paint(colour, fmt::emphasis::bold, c->name),
                         paint(colour, red, c->status),
                         c->diagnosis.empty() ? "" : ": " + c->diagnosis);
      }
    }
  }
  s += "\n" +
       paint(colour, fmt::emphasis::bold, fmt::format("Total: {} / {} points", earned, max)) + "\n";
  return s;
}

// JSON text of a report: invalid UTF-8 from a test's output replaced first.
std::string json_text(const std::string& text) {
  return clothlab::json_string(valid_utf8(text));
}

std::string xml_escape(const std::string& text) {
  std::string out;
  for (char ch : valid_utf8(text)) {
    if (ch == '&') {
      out += "&amp;";
    } else if (ch == '<') {
      out += "&lt;";
    } else if (ch == '>') {
      out += "&gt;";
    } else if (ch == '"') {
      out += "&quot;";
    } else if (static_cast<unsigned char>(ch) < 0x20 && ch != '\n' && ch != '\t') {
      out += '?';  // XML 1.0 forbids other control characters, even escaped
    } else {
      out += ch;
    }
  }
  return out;
}

// The text a report shows for one case: its status, first failure and own output.
std::string case_report(const Case& c, bool with_output) {
  std::string s = c.status + "\n";
  if (!c.message.empty()) s += c.message + "\n";
  if (!c.passed && !c.not_started && !c.not_compiled) {
    const std::string hint = lesson_hint(c.exercise);
    if (!hint.empty()) s += hint + "\n";
  }
  if (with_output && !c.output.empty()) s += "\noutput:\n" + c.output.substr(0, 8000);
  return s;
}

// A report goes only to a new file or over a regular one: never through a symbolic link, and
// never onto a device (as root, `--results /dev/null` would otherwise replace /dev/null).
void check_report_path(const std::string& option, const std::string& path) {
  if (path.empty()) return;
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(path, ec);
  if (ec || !fs::exists(status)) return;
  if (fs::is_symlink(status))
    fail(kExitBadInput,
         fmt::format("{} {}: is a symbolic link; give the path of a new or a regular file", option,
                     path));
  if (!fs::is_regular_file(status))
    fail(kExitBadInput,
         fmt::format("{} {}: is not a regular file (a device or a folder?); give the path of a "
                     "new or a regular file",
                     option, path));
}

// Written to a new file beside `path` (created here, so no one else's file or link is
// written through), then renamed over it: a reader never sees half a file.
void write_file(const std::string& path, const std::string& text) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(path, ec);
  if (!ec && fs::exists(status) && !fs::is_regular_file(status))
    fail(kExitBadInput, "not writing " + path + ": it is no longer a regular file");
  const std::string tmp = fmt::format("{}.{}.tmp", path, getpid());
  const int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) fail(kExitBadInput, "cannot write " + tmp + ": " + std::strerror(errno));
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      close(fd);
      fs::remove(tmp, ec);
      fail(kExitBadInput, "cannot write " + tmp + ": " + std::strerror(errno));
    }
    written += static_cast<std::size_t>(n);
  }
  close(fd);
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    fail(kExitBadInput, "cannot write " + path + ": " + ec.message());
  }
}

std::string gradescope_json(const std::vector<Case>& cases, double seconds,
                            const std::string& output) {
  int score = 0;
  std::string tests;
  for (const Case& c : cases) {
    score += c.passed ? c.points : 0;
    tests += fmt::format(
        "{}\n    {{\"name\": {}, \"number\": {}, \"score\": {}, \"max_score\": {}, "
        "\"status\": \"{}\", \"output\": {}, \"visibility\": \"{}\"}}",
        tests.empty() ? "" : ",", json_text(c.name), json_text(number_of(c.exercise)),
        c.passed ? c.points : 0, c.points, c.passed ? "passed" : "failed",
        json_text(case_report(c, true)), c.visibility);
  }
  return fmt::format(
      "{{\n  \"score\": {},\n  \"execution_time\": {:.3f},\n  \"output\": {},\n  \"tests\": [{}\n  "
      "]\n}}\n",
      score, seconds, json_text(output), tests);
}

std::string junit_xml(const std::vector<Case>& cases, double seconds) {
  std::string suites;
  int failures = 0;
  for (const Exercise& x : by_exercise(cases)) {
    std::string body;
    double time = 0;
    for (const Case* c : x.cases) {
      time += c->seconds;
      body += fmt::format(
          "    <testcase classname=\"{}\" name=\"{}\" file=\"{}\" line=\"{}\" time=\"{:.3f}\">\n",
          xml_escape(x.id), xml_escape(c->name), xml_escape(c->file), c->line, c->seconds);
      if (!c->passed) {
        const std::string first_line =
            c->status +
            (c->message.empty() ? "" : ": " + c->message.substr(0, c->message.find('\n')));
        body += fmt::format("      <failure message=\"{}\" type=\"{}\">{}</failure>\n",
                            xml_escape(first_line),
                            xml_escape(c->status.substr(0, c->status.find(':'))),
                            xml_escape(case_report(*c, false)));
      }
      if (!c->output.empty())
        body += fmt::format("      <system-out>{}</system-out>\n", xml_escape(c->output));
      body += "    </testcase>\n";
    }
    const int failed = static_cast<int>(x.cases.size()) - x.passed;
    failures += failed;
    suites += fmt::format(
        "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" time=\"{:.3f}\">\n{}  "
        "</testsuite>\n",
        xml_escape(x.id), x.cases.size(), failed, time, body);
  }
  return fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<testsuites name=\"clothlab grade\" tests=\"{}\" failures=\"{}\" errors=\"0\" "
      "time=\"{:.3f}\">\n{}</testsuites>\n",
      cases.size(), failures, seconds, suites);
}

// notes: what the grader says before the table (how a submission was built), also shown at the
// top of Gradescope's results.
void write_reports(const Options& o, const std::vector<Case>& cases, double seconds,
                   const std::string& notes) {
  if (!o.results.empty())
    write_file(o.results, gradescope_json(cases, seconds, notes + summary(cases, false)));
  if (!o.junit.empty()) write_file(o.junit, junit_xml(cases, seconds));
}

// Autolab reads the last line of the grader's output: {"scores": {...}, "scoreboard": [...]},
// one score per exercise (the problem names an Autolab course defines), the total on the
// scoreboard.
std::string autolab_line(const std::vector<Case>& cases) {
  std::string scores;
  int total = 0;
  for (const Exercise& x : by_exercise(cases)) {
    scores += fmt::format("{}{}: {}", scores.empty() ? "" : ", ", json_text(x.id), x.earned);
    total += x.earned;
  }
  return fmt::format("{{\"scores\": {{{}}}, \"scoreboard\": [{}]}}", scores, total);
}

// A GitHub Classroom autograding workflow with one step per exercise, worth that exercise's
// points (of the visible cases: the hidden ones are not in a student's repository). Each step
// passes only when every case of its exercise passes.
std::string classroom_workflow(const std::vector<Case>& cases) {
  std::string steps, env, runners;
  for (const Exercise& x : by_exercise(cases)) {
    int points = 0;
    for (const Case* c : x.cases)
      points += c->visibility == "visible" ? c->points : 0;
    if (points == 0) continue;
    std::string id = x.id;
    std::replace(id.begin(), id.end(), '.', '-');
    steps += fmt::format(
        "    - name: {0}\n"
        "      id: {1}\n"
        "      uses: classroom-resources/autograding-command-grader@v1\n"
        "      with:\n"
        "        test-name: {0}\n"
        "        setup-command: ''\n"
        "        command: ./build/clothlab grade --exercise {0} --require-full\n"
        "        timeout: 10\n"
        "        max-score: {2}\n",
        x.id, id, points);
    std::string upper = id;
    std::transform(upper.begin(), upper.end(), upper.begin(),
                   [](unsigned char ch) { return static_cast<char>(std::toupper(ch)); });
    env += fmt::format("        {}_RESULTS: \"${{{{steps.{}.outputs.result}}}}\"\n", upper, id);
    runners += (runners.empty() ? "" : ",") + id;
  }
  return fmt::format(
      "# GitHub Classroom autograding for clothlab, written by `clothlab grade --classroom PATH`\n"
      "# from the grading tests' points: one step per exercise, worth its points when every case\n"
      "# of the exercise passes. `./build/clothlab grade` shows a student the same cases.\n"
      "name: Autograding Tests\n"
      "'on':\n"
      "  - push\n"
      "  - workflow_dispatch\n"
      "  - repository_dispatch\n"
      "permissions:\n"
      "  checks: write\n"
      "  actions: read\n"
      "  contents: read\n"
      "jobs:\n"
      "  run-autograding-tests:\n"
      "    runs-on: ubuntu-latest\n"
      "    if: github.actor != 'github-classroom[bot]'\n"
      "    steps:\n"
      "    - name: Checkout code\n"
      "      uses: actions/checkout@v4\n"
      "    - name: Install the packages\n"
      "      run: sudo apt-get update && sudo apt-get install -y --no-install-recommends g++ "
      "cmake\n"
      "        make libeigen3-dev doctest-dev libfmt-dev libtomlplusplus-dev libcli11-dev\n"
      "    - name: Build the grader\n"
      "      run: cmake -S . -B build && cmake --build build --parallel 4 --target clothlab\n"
      "        grade-kit\n"
      "{}"
      "    - name: Autograding Reporter\n"
      "      uses: classroom-resources/autograding-grader-reporter@v1\n"
      "      env:\n"
      "{}"
      "      with:\n"
      "        runners: {}\n",
      steps, env, runners);
}

// --- The command --------------------------------------------------------------------------------

// A program of the build folder: the grading binary and the kernels programs are built next to
// clothlab.
std::string built_program(const std::string& name) {
  const fs::path path = fs::path(build_dir()) / name;
  if (!fs::exists(path)) {
    fail(kExitBadInput,
         fmt::format("{} does not exist: build it first with\n  cmake --build build --target {}",
                     path.string(), name));
  }
  return path.string();
}

bool selected(const Case& c, const std::string& filter) {
  return filter.empty() || c.exercise == filter || c.exercise.starts_with(filter + ".");
}

void print_points_table(const std::vector<Case>& cases) {
  std::size_t width = 4;
  for (const Case& c : cases)
    width = std::max(width, c.name.size());
  fmt::print("{:<10} {:<{}} {:>6}  {}\n", "Exercise", "Case", width, "Points", "Visibility");
  int total = 0, hidden = 0;
  for (const Case& c : cases) {
    fmt::print("{:<10} {:<{}} {:>6}  {}\n", c.exercise, c.name, width, c.points, c.visibility);
    total += c.points;
    hidden += c.visibility == "visible" ? 0 : c.points;
  }
  fmt::print("\nTotal: {} points in {} cases\n", total, cases.size());
  if (hidden > 0)
    fmt::print("of which in hidden tests, not shown to students before the due date: {} points\n",
               hidden);
}

// What the build of a submission took, left out and said, for the report.
std::string submission_notes(const SubmissionBuild& b) {
  auto names = [](const std::vector<std::string>& files) {
    std::string s;
    for (const std::string& f : files) {
      if (!s.empty()) s += ", ";
      s += printable(f);  // names the submission chose
    }
    return s;
  };
  std::string s;
  if (!b.taken.empty()) s += "Graded from the submission: " + names(b.taken) + "\n";
  if (!b.missing.empty())
    s += "Not in the submission (graded on the shipped stub): " + names(b.missing) + "\n";
  if (!b.ignored.empty()) s += "Ignored (not an exercise file): " + names(b.ignored) + "\n";
  if (!b.refused.empty()) s += "Refused (graded on the shipped stub): " + names(b.refused) + "\n";
  if (!b.built) s += "\nThe submission does not compile:\n" + indent(b.first_error, "  ") + "\n";
  return s + "\n";
}

std::string default_scratch() {
  return (fs::path(grade_kit_dir()).parent_path() / "grade-scratch").string();
}

// Where the student's own exercises are built for grading, kept from one grading to the next.
std::string own_scratch() {
  return (fs::path(grade_kit_dir()).parent_path() / "grade-own").string();
}

// A case that cannot run because what it would grade did not compile: `what` says so ("the
// submission does not compile"), `error` is the compiler's first error.
void mark_not_compiled(Case& c, const std::string& what, const std::string& error) {
  c.done = true;
  c.not_compiled = true;
  c.status = "not compiled";
  c.message = what + ":\n" + error;
  c.diagnosis = error.substr(0, error.find('\n'));
}

// "01_particles_and_euler.cpp" holds the exercises of lesson 01: ex01.1, ex01.2, ...
bool in_file(const Case& c, const std::string& file) {
  const std::string lesson = "ex" + file.substr(0, file.find('_'));
  return c.exercise == lesson || c.exercise.starts_with(lesson + ".");
}

// The student's own grading: exercises/ built afresh with the kit (only what changed is
// recompiled), a file that does not compile standing aside for its stub. Returns the binary to
// grade, or "" when nothing could be built; marks the cases that cannot be graded.
std::string build_own(const Options& o, std::vector<Case>& cases, std::string& notes, bool colour,
                      std::shared_ptr<void>& hold) {
  const std::string dir =
      o.exercises.empty() ? (fs::path(CLOTHLAB_SOURCE_DIR) / "exercises").string() : o.exercises;
  if (colour) fmt::print("building your exercises ...");
  std::fflush(stdout);
  SubmissionBuild build;
  try {
    build =
        build_submission(dir, o.scratch.empty() ? own_scratch() : o.scratch, o.build_timeout, true);
  } catch (const std::exception& e) {
    fail(kExitBadInput, e.what());
  }
  if (colour) fmt::print("\r\033[K");
  hold = build.hold;  // the scratch folder stays this grader's while the binary is graded
  for (const std::string& why : build.refused)
    notes += "Refused, graded on its shipped stub: exercises/" + printable(why) + "\n";
  if (!build.built) {
    if (g_interrupted) return "";
    build.first_error = printable(build.first_error);
    notes += "Your exercises do not build:\n" + indent(build.first_error, "  ") + "\n\n";
    for (Case& c : cases)
      mark_not_compiled(c, "the exercises do not build", build.first_error);
    return "";
  }
  for (SubmissionBuild::Broken& broken : build.broken) {
    broken.error = printable(broken.error);
    for (Case& c : cases) {
      if (!in_file(c, broken.name)) continue;
      mark_not_compiled(c, "exercises/" + broken.name + " does not compile", broken.error);
      c.broken_file = true;
    }
  }
  return build.binary;
}

void grade(const Options& o) {
  const bool submission = !o.submission.empty();
  // The student's own exercises, built before they are graded, so that a grade is never that
  // of a binary older than the files.
  const bool own = !submission && o.binary.empty() && o.impl == "student";
  const bool grading = !o.list && o.classroom.empty();
  check_report_path("--results", o.results);
  check_report_path("--junit", o.junit);
  check_report_path("--classroom", o.classroom);
  adopt_orphans();  // a process a case leaves behind is handed to the grader, which ends it
  if ((submission || own) &&
      (grading || !fs::exists(fs::path(grade_kit_dir()).parent_path() / "grade-cases"))) {
    const std::string why = update_grade_kit(o.build_timeout);
    if (!why.empty()) fail(kExitBadInput, why);
  }
  if (o.impl == "reference" && !CLOTHLAB_HAVE_SOLUTIONS && !submission && o.binary.empty())
    fail(kExitBadInput, "this is a student release: it has no reference solutions to grade");
  // The grading binary, and the kernels it calls: those of --impl, or those the kit builds below
  // from a submission or the student's exercises. (--binary: a binary with code of its own.)
  Grader grader;
  grader.binary = o.binary.empty() ? built_program("grade-cases") : o.binary;
  if (!fs::exists(grader.binary)) fail(kExitBadInput, grader.binary + " does not exist");
  if (!submission && !own && o.binary.empty())
    grader.kernels = built_program("grade-kernels-" + o.impl);
  std::vector<Case> cases = list_cases(grader.binary);
  // The hidden cases count only when an instructor asks for them: a student's grade has the
  // cases and points the lessons quote.
  if (!o.hidden) std::erase_if(cases, [](const Case& c) { return c.hidden_test; });
  if (!o.exercise.empty()) {
    std::erase_if(cases, [&](const Case& c) { return !selected(c, o.exercise); });
    if (cases.empty()) fail(kExitBadInput, "no grading case belongs to exercise " + o.exercise);
  }
  if (o.list) {
    print_points_table(cases);
    return;
  }
  if (!o.classroom.empty()) {
    write_file(o.classroom, classroom_workflow(cases));
    fmt::print("wrote {}\n", o.classroom);
    return;
  }

  const bool terminal = isatty(STDOUT_FILENO) != 0;
  const char* no_color = std::getenv("NO_COLOR");
  const bool colour = terminal && (no_color == nullptr || *no_color == '\0');

  g_interrupted = 0;
  InterruptGuard guard;
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  std::string notes;
  bool compiled = true;
  std::shared_ptr<void> hold;  // the scratch folder's lock, while its binary is graded
  // A submission is compiled, and its kernels run, as nobody (when the grader is root) and in the
  // sandbox where it works (sandbox.hpp); where it does not, the grader says loudly what the
  // submission can then do.
  Confinement confinement;
  if (submission && o.sandbox != "off") {
    std::string warnings;
    confinement = confine(o.sandbox, kit_inputs(), warnings);
    std::cout << std::flush;
    if (!warnings.empty()) std::cerr << "clothlab grade: warning: " << warnings;
    if (confinement.bwrap.empty() && o.sandbox == "on")
      fail(kExitBadInput,
           "--sandbox on: bubblewrap (bwrap) is not installed or cannot make namespaces here");
    if (confinement.bwrap.empty()) {
      std::cerr << "clothlab grade: WARNING: no sandbox (bubblewrap is not installed, or cannot "
                   "make namespaces here): the submission's code runs as "
                << (confinement.user.empty() ? "this user" : "the user nobody")
                << " and can read whatever that user can, the solutions and hidden tests "
                   "included. Install bubblewrap (Debian: apt-get install bubblewrap), or grade on "
                   "a machine that holds nothing else.\n";
    }
  }
  if (submission) {
    notes = "Submission: " + o.submission + "\n";
    write_reports(o, cases, elapsed(), notes);  // so even an interrupted build leaves results
    if (colour) fmt::print("building {} ...", o.submission);
    std::fflush(stdout);
    SubmissionBuild build;
    try {
      build = build_submission(o.submission, o.scratch.empty() ? default_scratch() : o.scratch,
                               o.build_timeout, false, o.sandbox != "off" ? &confinement : nullptr);
    } catch (const std::exception& e) {
      fail(kExitBadInput, e.what());
    }
    if (colour) fmt::print("\r\033[K");
    hold = build.hold;
    build.first_error = printable(build.first_error);
    notes += submission_notes(build);
    fmt::print("{}", notes);
    compiled = build.built;
    if (compiled) {
      grader.kernels = build.binary;
    } else if (!g_interrupted) {
      for (Case& c : cases)
        mark_not_compiled(c, "the submission does not compile", build.first_error);
    }
  }
  if (own) {
    grader.kernels = build_own(o, cases, notes, colour, hold);
    compiled = !grader.kernels.empty();
    fmt::print("{}", notes);
  }
  if (submission && o.sandbox != "off") grader.sandbox = confinement.kernels(grader.kernels);
  for (std::size_t i = 0; compiled && i < cases.size() && !g_interrupted; ++i) {
    if (cases[i].done) continue;  // not compiled
    if (colour) fmt::print("\r\033[K[{}/{}] {}", i + 1, cases.size(), cases[i].name.substr(0, 70));
    std::fflush(stdout);
    run_case(grader, cases[i], o.timeout);
    // After every case, so an interrupted run leaves results.
    write_reports(o, cases, elapsed(), notes);
  }
  if (colour) fmt::print("\r\033[K");
  std::fflush(stdout);

  fmt::print("{}", summary(cases, colour));
  write_reports(o, cases, elapsed(), notes);
  if (g_interrupted)
    fail(kExitInterrupted, "interrupted: the results of the cases run so far are written");
  if (o.autolab) fmt::print("{}\n", autolab_line(cases));

  if (o.require_full) {
    const auto failed =
        std::count_if(cases.begin(), cases.end(), [](const Case& c) { return !c.passed; });
    if (failed > 0)
      fail(kExitFailed,
           fmt::format("--require-full: {} of {} cases did not pass", failed, cases.size()));
  }
  if (o.require_zero) {
    std::string scored;
    for (const Exercise& x : by_exercise(cases)) {
      if (x.earned > 0)
        scored += fmt::format("\n  {} scores {} / {} points", x.id, x.earned, x.max);
    }
    if (!scored.empty()) {
      fail(kExitFailed,
           "--require-zero: these exercises score points, so their tests cannot fail:" + scored);
    }
  }
}

// The exercise files of the student, and when each last changed: what `watch` waits on.
using Snapshot = std::vector<std::pair<std::string, fs::file_time_type>>;
Snapshot exercise_files(const fs::path& dir) {
  Snapshot files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() != ".cpp") continue;
    files.emplace_back(entry.path().filename().string(), entry.last_write_time(ec));
  }
  std::sort(files.begin(), files.end());
  return files;
}

// `clothlab watch`: grades, then grades again each time an exercise file is saved.
void watch(Options o) {
  const fs::path dir =
      o.exercises.empty() ? fs::path(CLOTHLAB_SOURCE_DIR) / "exercises" : fs::path(o.exercises);
  const bool terminal = isatty(STDOUT_FILENO) != 0;
  const std::string what = o.exercise.empty() ? "every exercise" : o.exercise;
  InterruptGuard guard;  // Ctrl-C while waiting ends the watch
  std::string changed;
  for (int round = 1;; ++round) {
    if (terminal) fmt::print("\033[2J\033[H");  // a clear screen for each grading
    fmt::print("clothlab watch: {}, graded again each time you save a file in {}/{}\n\n", what,
               relative_path(dir.string()), changed.empty() ? "" : " (" + changed + " changed)");
    std::fflush(stdout);
    try {
      grade(o);
    } catch (const CLI::RuntimeError& e) {
      if (e.get_exit_code() == kExitInterrupted) throw;  // interrupted while grading
      // Anything else the grader could not do is said; the next save may mend it.
    }
    if (o.rounds > 0 && round >= o.rounds) return;
    fmt::print("\nwaiting for a change in {}/ (Ctrl-C to stop)\n", relative_path(dir.string()));
    std::fflush(stdout);
    const Snapshot before = exercise_files(dir);
    Snapshot now = before;
    while (now == before) {
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      if (g_interrupted) {
        fmt::print("stopped\n");
        return;
      }
      now = exercise_files(dir);
    }
    changed.clear();
    for (const auto& file : now) {
      if (std::find(before.begin(), before.end(), file) == before.end())
        changed += (changed.empty() ? "" : ", ") + file.first;
    }
    // An editor may write a file in more than one go.
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
  }
}

}  // namespace

void add_watch_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "watch", "Grade your exercises, then again each time you save one (Ctrl-C to stop)");
  cmd->add_option("exercise", o->exercise, "Watch one lesson (ex01) or one exercise (ex01.2)")
      ->check(CLI::Validator(
          [](std::string& s) {
            return is_exercise_id(s, true) ? std::string() : "expected exNN or exNN.k";
          },
          "exNN[.k]"));
  cmd->add_option("--timeout", o->timeout, "Seconds a case may run before it is stopped")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--exercises", o->exercises, "The folder of exercise files")->group("");
  cmd->add_option("--scratch", o->scratch, "Where to build them")->group("");
  cmd->add_option("--rounds", o->rounds, "Stop after this many gradings")->group("");
  cmd->callback([o] { watch(*o); });
}

void add_grade_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("grade", "Run the grading tests and score each exercise");
  cmd->add_option("--impl", o->impl,
                  "Which kernels to grade: your exercises (built first, so the grade is always "
                  "that of the files as saved), the reference or the shipped stubs")
      ->check(CLI::IsMember({"student", "reference", "stubs"}))
      ->capture_default_str();
  cmd->add_flag("--hidden", o->hidden,
                "Also the hidden cases of tests/grade-hidden/ (for instructors: a student's "
                "grade leaves them out)");
  cmd->add_option("--exercises", o->exercises, "Grade the exercise files in this folder as yours")
      ->group("");
  cmd->add_option("--exercise", o->exercise, "Grade one lesson (ex01) or one exercise (ex01.2)")
      ->check(CLI::Validator(
          [](std::string& s) {
            return is_exercise_id(s, true) ? std::string() : "expected exNN or exNN.k";
          },
          "exNN[.k]"));
  cmd->add_flag("--list", o->list, "Print the points table without running anything");
  cmd->add_option("--timeout", o->timeout, "Seconds a case may run before it is stopped")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--results", o->results, "Write Gradescope results.json here");
  cmd->add_option("--junit", o->junit, "Write JUnit XML here");
  cmd->add_flag("--require-full", o->require_full, "Exit with status 1 unless every case passed");
  cmd->add_flag("--require-zero", o->require_zero,
                "Exit with status 1 unless every exercise scored zero");
  CLI::Option* binary = cmd->add_option("--binary", o->binary,
                                        "Grade this doctest binary (built with grade_main.cpp)")
                            ->group("");
  cmd->add_option("--submission", o->submission,
                  "Grade the exercise files in this folder (a student's submission), built in a "
                  "scratch folder")
      ->excludes(binary);
  cmd->add_option("--scratch", o->scratch,
                  "Where to build a submission (default: grade-scratch next to clothlab; "
                  "grade-own for your exercises)");
  cmd->add_option("--build-timeout", o->build_timeout,
                  "Seconds configuring, then compiling, a submission may take")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--sandbox", o->sandbox,
                  "Run a submission's cases in bubblewrap: auto (where it works, else warn), on "
                  "(refuse to grade without it) or off")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  cmd->add_flag("--autolab", o->autolab,
                "End with Autolab's one-line JSON summary of the scores per exercise");
  cmd->add_option("--classroom", o->classroom,
                  "Write a GitHub Classroom workflow (one step per exercise) here; grade nothing");
  cmd->callback([o] { grade(*o); });
}

}  // namespace clothlab::app
