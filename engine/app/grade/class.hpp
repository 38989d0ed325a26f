// class.hpp: `clothlab grade --class DIR`, a class graded in one command.
//
// Every submission folder under DIR (a folder per student, or Gradescope's export: a
// submission_metadata.yml beside a submission_<id>/ folder per submission) is graded by a grader
// of its own (`clothlab grade --submission`, so that a class is graded exactly as one student is),
// as many at a time as there are cores, on the grading binary and engine built once. A submission
// whose files, and whose grading, are as when it was last graded is not graded again. The reports
// go to REPORT_DIR: a JSON per submission, class.csv, and index.html with the class table, what
// the class got wrong, and the similarity report (Debian's sim_c++, on the students' code less the
// shipped stubs).
#pragma once

#include <string>
#include <vector>

#include "app/grade/cases.hpp"

namespace clothlab::app::grading {

struct ClassOptions {
  std::string dir;      // the class: a folder of submission folders
  std::string out;      // REPORT_DIR
  int jobs = 0;         // submissions graded at a time (0: one per core)
  double timeout = 10;  // per case [s]
  double build_timeout = 600;
  std::string sandbox = "auto";
  bool kernels_as_root = false;
  bool hidden = false;
  std::string exercise;  // only this lesson or exercise
};

// Grades the class; fails (kExitBadInput) when DIR holds no submission or REPORT_DIR cannot be
// written, and (kExitInterrupted) when interrupted: what was graded is kept, and resumed from.
void grade_class(const ClassOptions& o);

// What one grader of a class writes for its submission (`--record PATH`): every case's verdict,
// and where the time went (`build_seconds` building the kernels, the rest running cases).
std::string submission_record(const std::vector<Case>& cases, const std::string& notes,
                              double build_seconds, double seconds);

}  // namespace clothlab::app::grading
