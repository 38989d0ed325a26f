// grade.hpp: the `clothlab grade` subcommand.
//
// The grader runs the grading tests (tests/grade/NN_*.cpp, built into grade-cases next to this
// program) one case per process, so that a crash or an endless loop costs that case only, with
// the exercise kernels under test in a process of their own (grade-kernels-reference, -stubs, or
// those it builds from the student's exercises or a submission), and reports points per exercise
// with hints that point to the lesson. It also writes Gradescope results.json and JUnit XML.
//
// It lives in app/grade/, a file per job: cases (what a case is and how its verdict is reached),
// protocol (the grading binary's line protocol), exercises (exercise IDs and lesson hints),
// reports (every report format), text (text made safe to show) and command (the options and the
// two subcommands).
#pragma once

namespace CLI {
class App;
}

namespace clothlab::app {

// Adds the `grade` subcommand to app. On failure its callback throws CLI::RuntimeError with the
// exit status (exit_codes.hpp: kExitFailed when --require-full or --require-zero is not met,
// kExitBadInput when the grader cannot run, kExitInterrupted), which CLI11_PARSE / app.exit()
// turn into main's return value.
void add_grade_command(CLI::App& app);

// Adds `watch [exNN[.k]]`: grades the student's exercises, then again on every save.
void add_watch_command(CLI::App& app);

}  // namespace clothlab::app
