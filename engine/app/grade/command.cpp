// command.cpp: the `clothlab grade` and `clothlab watch` subcommands (app/grade.hpp): their
// options, building what is graded (the student's exercises or a submission), grading the cases
// one by one and writing the reports as they come, and watching the exercise files.
#include "app/exit_codes.hpp"
#include "app/grade.hpp"
#include "app/grade/cases.hpp"
#include "app/grade/class.hpp"
#include "app/grade/exercises.hpp"
#include "app/grade/reports.hpp"
#include "app/grade/text.hpp"
#include "app/process.hpp"
#include "app/sandbox.hpp"
#include "app/submission.hpp"

#include <unistd.h>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <numeric>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace clothlab::app {

using namespace grading;

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

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
  bool kernels_as_root = false;  // --sandbox off as root: said twice, so run the kernels as root
  bool autolab = false;          // end with Autolab's one-line JSON score summary
  std::string classroom;         // write a GitHub Classroom workflow here, and grade nothing
  bool hidden = false;           // also the hidden cases of tests/grade-hidden/ (instructors)
  std::string exercises;         // hidden: the student's exercise files; default exercises/
  int rounds = 0;                // watch: stop after this many gradings (0: never; for tests)
  std::string web_build;         // watch, hidden: rebuild the student pages of this web build
  std::string class_dir;         // grade every submission folder in it (class.hpp)
  std::string out;               // --class: where the reports go
  int jobs = 0;                  // --class: submissions graded at a time (0: one per core)
  std::string record;            // hidden: write the submission's record here (for --class)
  bool kit_ready = false;        // hidden: the kit is built (by --class), do not build it again
};

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

// What the build of the exercise files took, left out and refused, and why nothing could be
// built when nothing could, for the report. The names are the submission's choice: each is shown
// escaped on one line, so that none can draw a line of the report.
std::string build_notes(const SubmissionBuild& b, bool submission) {
  auto names = [](const std::vector<std::string>& files) {
    std::string s;
    for (const std::string& f : files) {
      if (!s.empty()) s += ", ";
      s += one_line(f);
    }
    return s;
  };
  std::string s;
  if (submission) {
    if (!b.taken.empty()) s += "Graded from the submission: " + names(b.taken) + "\n";
    if (!b.missing.empty())
      s += "Not in the submission (graded on the shipped stub): " + names(b.missing) + "\n";
    if (!b.ignored.empty()) s += "Ignored (not an exercise file): " + names(b.ignored) + "\n";
  }
  if (!b.refused.empty()) s += "Refused (graded on the shipped stub): " + names(b.refused) + "\n";
  if (!b.built) {
    s += submission ? "\nThe submission does not compile:\n" : "Your exercises do not build:\n";
    s += indent(b.first_error, "  ") + "\n";
  }
  return s.empty() ? s : s + "\n";
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
  c.message = what + ":\n" + indent(error, "  ");
  c.diagnosis = error.substr(0, error.find('\n'));
}

// "01_particles_and_euler.cpp" holds the exercises of lesson 01: ex01.1, ex01.2, ...
bool in_file(const Case& c, const std::string& file) {
  const std::string lesson = "ex" + file.substr(0, file.find('_'));
  return c.exercise == lesson || c.exercise.starts_with(lesson + ".");
}

// Builds the kernels program of the exercise files in `dir`, in `scratch`, by the one code path
// both gradings take: the student's own (exercises/ is `dir`) and a submission's (`submission`,
// as run_autograder grades), so that the same files get the same grade either way. A file that
// does not compile, or includes what it may not, gives way to its shipped stub and costs its own
// exercises only: they are marked not compiled, with its error, and the others are graded.
// Returns the kernels program, or "" when nothing could be built (every case is then marked, but
// when the grader was interrupted); `notes` gets what the build said.
std::string build_kernels(const std::string& dir, const std::string& scratch, bool submission,
                          const Options& o, const Confinement* confinement,
                          std::vector<Case>& cases, std::string& notes, bool colour,
                          std::shared_ptr<void>& hold) {
  if (colour)
    fmt::print("building {} ...", submission ? one_line(dir) : std::string("your exercises"));
  std::fflush(stdout);
  SubmissionBuild build;
  try {
    build = build_submission(dir, scratch, o.build_timeout, confinement);
  } catch (const std::exception& e) {
    fail(kExitBadInput, e.what());
  }
  if (colour) fmt::print("\r\033[K");
  hold = build.hold;  // the scratch folder stays this grader's while the binary is graded
  build.first_error = printable(build.first_error);
  notes += build_notes(build, submission);
  if (!build.built) {
    if (g_interrupted) return "";
    for (Case& c : cases) {
      mark_not_compiled(
          c, submission ? "the submission does not compile" : "your exercises do not build",
          build.first_error);
    }
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

// notes: what the grader says before the table (how a submission was built), also shown at the
// top of Gradescope's results.
void write_reports(const Options& o, const std::vector<Case>& cases, double seconds,
                   const std::string& notes) {
  if (!o.results.empty()) write_file(o.results, gradescope_json(cases, seconds, notes));
  if (!o.junit.empty()) write_file(o.junit, junit_xml(cases, seconds));
}

void grade(const Options& o) {
  if (!o.class_dir.empty()) {
    if (!o.submission.empty() || o.impl != "student" || o.list || !o.classroom.empty() ||
        !o.results.empty() || !o.junit.empty())
      fail(kExitBadInput,
           "--class grades every submission in its folder and writes its own reports: it takes "
           "none of --submission, --impl, --list, --classroom, --results or --junit");
    grade_class({o.class_dir, o.out, o.jobs, o.timeout, o.build_timeout, o.sandbox,
                 o.kernels_as_root, o.hidden, o.exercise});
    return;
  }
  const bool submission = !o.submission.empty();
  // The student's own exercises, built before they are graded, so that a grade is never that
  // of a binary older than the files.
  const bool own = !submission && o.binary.empty() && o.impl == "student";
  const bool grading = !o.list && o.classroom.empty();
  check_report_path("--results", o.results);
  check_report_path("--junit", o.junit);
  check_report_path("--classroom", o.classroom);
  adopt_orphans();  // a process a case leaves behind is handed to the grader, which ends it
  if ((submission || own) && !o.kit_ready &&
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
  double build_seconds = 0;    // building the kernels
  // A submission is compiled, and its kernels run, as nobody (when the grader is root) and in the
  // sandbox where it works (sandbox.hpp); where it does not, the grader says loudly what the
  // submission can then do.
  Confinement confinement;
  if (submission) {
    std::string warnings;
    if (o.sandbox != "off") confinement = confine(o.sandbox, kit_inputs(), warnings);
    std::cout << std::flush;
    if (!warnings.empty()) std::cerr << "clothlab grade: warning: " << warnings;
    if (confinement.bwrap.empty() && o.sandbox == "on")
      fail(kExitBadInput,
           "--sandbox on: bubblewrap (bwrap) is not installed or cannot make namespaces here");
    const bool as_root = geteuid() == 0 && confinement.user.empty();
    if (o.sandbox == "off" && as_root && !o.kernels_as_root) {
      fail(kExitBadInput,
           "--sandbox off as root: the submission's code would run as root, with no sandbox, and "
           "could change the grading binary and so every later grade. Grade with --sandbox auto "
           "(the user nobody, and bubblewrap where it works), or, on a machine that holds nothing "
           "else, say it twice: --sandbox off --kernels-as-root");
    }
    if (confinement.bwrap.empty()) {
      std::cerr << "clothlab grade: WARNING: no sandbox ("
                << (o.sandbox == "off" ? "--sandbox off"
                                       : "bubblewrap is not installed, or cannot make namespaces "
                                         "here")
                << "): the submission's code runs as "
                << (!confinement.user.empty()
                        ? "the user nobody and can read whatever nobody can, the solutions "
                          "included (not the hidden tests)"
                    : as_root ? "root and can read anything on this machine, the solutions and "
                                "hidden tests included, and signal any process"
                              : "this user and can read whatever this user can, the solutions "
                                "and hidden tests included")
                << ". Install bubblewrap (Debian: apt-get install bubblewrap), or grade on "
                   "a machine that holds nothing else.\n";
    }
    // What holds the hidden tests is root's alone, wherever the submission's code runs.
    if (geteuid() == 0) keep_hidden_tests_to_owner(build_dir(), CLOTHLAB_SOURCE_DIR);
  }
  if (submission || own) {
    if (submission) {
      notes = "Submission: " + one_line(o.submission) + "\n";
      write_reports(o, cases, elapsed(), notes);  // so even an interrupted build leaves results
    }
    const std::string dir = submission ? o.submission
                            : o.exercises.empty()
                                ? (fs::path(CLOTHLAB_SOURCE_DIR) / "exercises").string()
                                : o.exercises;
    const std::string scratch = !o.scratch.empty() ? o.scratch
                                : submission       ? default_scratch()
                                                   : own_scratch();
    const auto build_start = Clock::now();
    grader.kernels = build_kernels(dir, scratch, submission, o, submission ? &confinement : nullptr,
                                   cases, notes, colour, hold);
    build_seconds = std::chrono::duration<double>(Clock::now() - build_start).count();
    compiled = !grader.kernels.empty();
    fmt::print("{}", notes);
  }
  if (submission && compiled)
    grader.sandbox = confinement.kernels(built_program("grade-confine"), grader.kernels);
  // The cases a student sees now run first, so that no output a student sees comes from a run
  // after a hidden case's: without the sandbox, kernels could keep what a hidden case gave them
  // (in /tmp, say) and print it in a later case.
  std::vector<std::size_t> order(cases.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_partition(order.begin(), order.end(),
                        [&](std::size_t i) { return cases[i].visibility == "visible"; });
  for (std::size_t k = 0; compiled && k < order.size() && !g_interrupted; ++k) {
    Case& c = cases[order[k]];
    if (c.done) continue;  // not compiled
    if (colour)
      fmt::print("\r\033[K[{}/{}] {}", k + 1, cases.size(), one_line(c.name).substr(0, 70));
    std::fflush(stdout);
    run_case(grader, c, o.timeout);
    // After every case, so an interrupted run leaves results.
    write_reports(o, cases, elapsed(), notes);
  }
  if (colour) fmt::print("\r\033[K");
  std::fflush(stdout);

  // Autolab shows the grader's whole output to the student: then only what a student may see.
  fmt::print("{}", summary(cases, colour, o.autolab ? Audience::student : Audience::grader));
  write_reports(o, cases, elapsed(), notes);
  if (g_interrupted)
    fail(kExitInterrupted, "interrupted: the results of the cases run so far are written");
  if (o.autolab) fmt::print("{}\n", autolab_line(cases));
  if (!o.record.empty())
    write_file(o.record, submission_record(cases, notes, build_seconds, elapsed()));

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

// A value of a CMake cache (a line KEY:TYPE=VALUE), or "" where there is none.
std::string cache_value(const fs::path& cache, const std::string& key) {
  std::ifstream in(cache);
  for (std::string line; std::getline(in, line);) {
    const size_t equals = line.find('=');
    if (line.starts_with(key + ":") && equals != std::string::npos) return line.substr(equals + 1);
  }
  return "";
}

// The student's live pages (engine/web/), rebuilt on each save where the build can make them
// (it found emscripten when it was configured): the pages of the course's exercises/, by the
// build's `web-student` target; not those of a folder given with --exercises, unless --web-build
// names a web build of the student pages alone made for that folder (ENGINE_FROM in
// engine/web/CMakeLists.txt; the test of watch's pages makes one). Says where they are, or why
// they could not be rebuilt.
void rebuild_student_pages(const Options& o) {
#if CLOTHLAB_WEB_STUDENT
  const std::string build = build_dir();
  std::string dir = build, target = "web-student";
  fs::path web = fs::path(build) / "web";
  if (!o.web_build.empty()) {
    dir = o.web_build;
    web = o.web_build;
    target = "pages-student";
  } else if (!o.exercises.empty()) {
    return;
  }
  if (!fs::exists(web / "CMakeCache.txt")) {
    // Never built here: the first build takes many minutes, too long to start on a save.
    fmt::print(
        "\n(your live pages are not built: `cmake --build {} --target {}` builds them once, and "
        "watch then rebuilds them each time you save)\n",
        relative_path(dir), target);
    return;
  }
  std::string pages = cache_value(web / "CMakeCache.txt", "PAGES_DIR");
  if (pages.empty()) pages = (fs::path(build) / "pages").string();
  fmt::print("\nrebuilding your live pages (cmake --build {} --target {}) ...\n",
             relative_path(dir), target);
  std::fflush(stdout);
  const Clock::time_point start = Clock::now();
  const ProcessResult r =
      run_process({CLOTHLAB_CMAKE_COMMAND, "--build", dir, "--target", target}, 900);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (r.interrupted) return;
  if (r.exit_code == 0 && r.signal == 0 && !r.timed_out) {
    fmt::print(
        "your live pages, rebuilt in {:.1f} s: open {}/NN-name-student.html in a "
        "browser (reload it if it is open)\n",
        seconds, relative_path(pages));
    return;
  }
  // The build's last lines: the compiler's error, or what else stopped it.
  std::string tail = r.output;
  size_t at = tail.size();
  for (int lines = 0; lines < 12 && at > 0; ++lines)
    at = tail.rfind('\n', at - 1);
  if (at != std::string::npos && at > 0) tail = tail.substr(at + 1);
  fmt::print("your live pages could not be rebuilt ({}):\n{}\n",
             r.timed_out ? "the build took too long" : "the build failed", indent(tail, "  "));
#else
  (void)o;  // no emscripten when the build was configured: no live pages to rebuild
#endif
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
    rebuild_student_pages(o);
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
      if (std::find(before.begin(), before.end(), file) != before.end()) continue;
      if (!changed.empty()) changed += ", ";
      changed += one_line(file.first);
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
  cmd->add_option("--web-build", o->web_build,
                  "Rebuild the student pages of this web build (one made for --exercises)")
      ->group("");
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
  cmd->add_flag("--kernels-as-root", o->kernels_as_root,
                "With --sandbox off as root: run the submission's code as root all the same (on a "
                "machine that holds nothing else)");
  cmd->add_flag("--autolab", o->autolab,
                "End with Autolab's one-line JSON summary of the scores per exercise");
  cmd->add_option("--classroom", o->classroom,
                  "Write a GitHub Classroom workflow (one step per exercise) here; grade nothing");
  CLI::Option* class_dir =
      cmd->add_option("--class", o->class_dir,
                      "Grade every submission folder in this folder (a folder per student, or "
                      "Gradescope's export), a few at a time, into --out")
          ->excludes(binary);
  cmd->add_option("--out", o->out,
                  "With --class: where the reports go (default: the class folder's name with "
                  "-report)")
      ->needs(class_dir);
  cmd->add_option("--jobs", o->jobs,
                  "With --class: submissions graded at a time (default: one "
                  "per core)")
      ->check(CLI::Range(1, 256))
      ->needs(class_dir);
  cmd->add_option("--record", o->record, "Write the submission's record here")->group("");
  cmd->add_flag("--kit-ready", o->kit_ready, "The kit is built: do not build it")->group("");
  cmd->callback([o] { grade(*o); });
}

}  // namespace clothlab::app
