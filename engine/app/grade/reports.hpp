// reports.hpp: every report of a grading: the summary table the grader prints, the points table
// of --list, Gradescope's results.json, JUnit XML, Autolab's one-line score summary and a GitHub
// Classroom workflow; and how a report file is written.
#pragma once

#include <string>
#include <vector>

#include "app/grade/cases.hpp"

namespace clothlab::app::grading {

// The cases of one exercise, and its points.
struct Exercise {
  std::string id;
  std::vector<const Case*> cases;
  int earned = 0, max = 0, passed = 0;
};

// The cases grouped by exercise, in the order of their first case.
std::vector<Exercise> by_exercise(const std::vector<Case>& cases);

// Who reads a summary. The grader's user sees every case graded. A student sees only the cases
// whose visibility is "visible", the others at most as a count: Gradescope shows results.json's
// top-level output to the student at once, whatever its tests' visibility (and Autolab shows the
// grader's whole output), so nothing of a hidden case (its name, check, hint, expected value or
// points) may be in it.
enum class Audience { grader, student };

// The table the grader prints at the end: points and cases per exercise, each failing exercise's
// first failure in full and its other failures in a line each; with ANSI colours when `colour`.
// Names and messages are shown escaped on one line (one_line), so none can draw a line of the
// table.
std::string summary(const std::vector<Case>& cases, bool colour,
                    Audience audience = Audience::grader);

// Prints the points table of `clothlab grade --list`: every case, its points and visibility.
void print_points_table(const std::vector<Case>& cases);

// Gradescope's results.json: the score, `seconds` the grading took, a test per case (each with
// its visibility), and at the top, which every student sees, `notes` and the student's summary.
// The grader's own output (stdout) is marked as the instructor's alone.
std::string gradescope_json(const std::vector<Case>& cases, double seconds,
                            const std::string& notes);

// JUnit XML: a test suite per exercise, a test case per case, hidden ones included (the
// instructor's report: no autograder shows it to students). Well-formed whatever bytes a name or
// message holds.
std::string junit_xml(const std::vector<Case>& cases, double seconds);

// Autolab's last line of output: the score of each exercise and the total.
std::string autolab_line(const std::vector<Case>& cases);

// A GitHub Classroom autograding workflow with one step per exercise.
std::string classroom_workflow(const std::vector<Case>& cases);

// Fails (kExitBadInput) unless `path` (given with `option`) is empty, new, or a regular file.
void check_report_path(const std::string& option, const std::string& path);

// Writes `text` to `path` through a new file renamed over it; fails (kExitBadInput) when it
// cannot.
void write_file(const std::string& path, const std::string& text);

}  // namespace clothlab::app::grading
