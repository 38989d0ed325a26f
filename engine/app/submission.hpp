// submission.hpp: building the grading binary of a student's submission, for `clothlab grade
// --submission DIR`.
//
// The submission's exercise files are copied into a scratch folder (never into the user's
// exercises/), a shipped stub stands in for each file the submission lacks, and a small CMake
// project that the build generated next to clothlab (grade-kit/) compiles those files alone and
// links them with the engine's objects the project's build already made, into the kernels
// program the grading binary calls (grade-kernels, see tests/grade/harness/kernel_wire.hpp).
// Nothing of the submission runs here: it is only compiled, and no test is linked with it.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace clothlab::app {

struct Confinement;

struct SubmissionBuild {
  bool built = false;
  std::string binary;       // the kernels program of the submission, when built
  std::string first_error;  // why it was not built: the compiler's first error, or what failed
  std::string log;          // the build's output, with scratch paths shown as exercises/...
  std::vector<std::string> taken;    // exercise files taken from the submission
  std::vector<std::string> missing;  // exercise files it lacks (graded on the shipped stub)
  std::vector<std::string> ignored;  // other .cpp files in it, left out
  // Exercise files refused, each with why ("01_x.cpp (a symbolic link)"): graded on the stub.
  std::vector<std::string> refused;
  // The exercise files that did not compile or link, or that include what they may not, each with
  // the compiler's or the linker's first error (or why it was refused); the binary holds their
  // shipped stubs instead.
  struct Broken {
    std::string name;   // "01_particles_and_euler.cpp"
    std::string error;  // "exercises/01_particles_and_euler.cpp:12:5: error: ..."
  };
  std::vector<Broken> broken;
  // The scratch folder's lock, held as long as this is kept: no other grader builds there
  // meanwhile. (A grader that finds it held builds in a folder of its own, removed with this.)
  std::shared_ptr<void> hold;
};

// Builds the grading binary of the submission in `submission_dir` (exercise files named as in
// exercises/, at its top or in its exercises/ folder) inside `scratch_dir`, giving up after
// `timeout` seconds. Throws std::runtime_error when the build kit is missing or the submission
// folder does not exist; a submission that does not compile is not an error but a result.
// The scratch folder keeps its build, so grading the same files again recompiles only the files
// that changed. An exercise file that does not compile, that includes what it may not, or that
// the linker blames (it calls what is defined nowhere, or defines again what another file
// defines) is replaced by its shipped stub, so that it costs its own exercises only and the other
// files' exercises are graded on what they say: the student's own loop and a submission's grading
// are the same build, so the same files get the same grade either way. Only an error no file can
// be blamed for leaves no binary.
// With `confinement` (a submission's build), the build runs confined: it sees the system, the
// kit's inputs (kit_inputs) and the scratch folder alone, and it starts from no object of an
// earlier build, so nothing compiled from another submission is there to read.
SubmissionBuild build_submission(const std::string& submission_dir, const std::string& scratch_dir,
                                 double timeout, const Confinement* confinement = nullptr);

// One exercise file of the project and its shipped stub, as the build kit lists them.
struct KitExercise {
  std::string name;  // "01_particles_and_euler.cpp"
  std::filesystem::path stub;
};

// The exercise files the kit knows (grade-kit/exercises.txt); throws std::runtime_error when the
// kit is missing.
std::vector<KitExercise> kit_exercise_files();

// Where a submission in `dir` keeps the exercise file `name`: at its top, or in its exercises/
// folder (a copy of the starter repository). Empty when it has neither, or when what it has there
// is refused: only a regular file inside the submission folder is taken, never a symbolic link (to
// solutions/, say), a device (/dev/zero), a folder or a file of more than 1 MiB. `why` then says
// which.
std::filesystem::path find_exercise_file(const std::filesystem::path& dir, const std::string& name,
                                         std::string& why);

// What a submission's build reads besides the system and its own files: the kit, the engine's
// headers, and the objects of the project's build it links (grade-kit/inputs.txt).
std::vector<std::string> kit_inputs();

// Brings what the kit links (the engine, the kernels' main, the shipped stubs) and the grading
// binary up to date, by building the target grade-kit of the project's build folder (the folder
// this program is in) when it is one. Returns "" or why it failed.
std::string update_grade_kit(double timeout);

// The build folder the running program belongs to: the folder of clothlab (and of the grading
// binaries), which is also the one above student-programs/, where the student programs live.
std::string build_dir();

// The build kit generated next to the running clothlab: <build folder>/grade-kit.
std::string grade_kit_dir();

// The first compiler or linker error in a build log ("exercises/01_x.cpp:12:5: error: ..."),
// with the lines that explain it, at most `max_lines` lines; "" when there is none. With
// `in_file`, only an error reported at a line of that file counts.
std::string first_build_error(const std::string& log, int max_lines = 8,
                              const std::string& in_file = "");

}  // namespace clothlab::app
