// submission.hpp: building the grading binary of a student's submission, for `clothlab grade
// --submission DIR`.
//
// The submission's exercise files are copied into a scratch folder (never into the user's
// exercises/), a shipped stub stands in for each file the submission lacks, and a small CMake
// project that the build generated next to clothlab (grade-kit/) compiles those files alone and
// links them with the engine and grading-test objects the project's build already made. Nothing
// of the submission runs here: it is only compiled.
#pragma once

#include <string>
#include <vector>

namespace clothlab::app {

struct SubmissionBuild {
  bool built = false;
  std::string binary;       // the grading binary on the submission's kernels, when built
  std::string first_error;  // why it was not built: the compiler's first error, or what failed
  std::string log;          // the build's output, with scratch paths shown as exercises/...
  std::vector<std::string> taken;    // exercise files taken from the submission
  std::vector<std::string> missing;  // exercise files it lacks (graded on the shipped stub)
  std::vector<std::string> ignored;  // other .cpp files in it, left out
};

// Builds the grading binary of the submission in `submission_dir` (exercise files named as in
// exercises/, at its top or in its exercises/ folder) inside `scratch_dir`, giving up after
// `timeout` seconds. Throws std::runtime_error when the build kit is missing or the submission
// folder does not exist; a submission that does not compile is not an error but a result.
SubmissionBuild build_submission(const std::string& submission_dir, const std::string& scratch_dir,
                                 double timeout);

// The build kit generated next to the running clothlab: <dir of clothlab>/grade-kit.
std::string grade_kit_dir();

// The first compiler or linker error in a build log ("exercises/01_x.cpp:12:5: error: ..."),
// with the lines that explain it, at most `max_lines` lines; "" when there is none.
std::string first_build_error(const std::string& log, int max_lines = 8);

}  // namespace clothlab::app
