// submission.cpp: see submission.hpp.
#include "app/submission.hpp"

#include <unistd.h>

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "app/process.hpp"

namespace clothlab::app {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Copies `from` to `to` only when the contents differ, so that the scratch build recompiles only
// the files that changed since the submission graded before.
void copy_if_different(const fs::path& from, const fs::path& to) {
  if (fs::exists(to) && read_text(from) == read_text(to)) return;
  fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

// One exercise file of the project and the shipped stub of it, as the kit lists them.
struct ExerciseFile {
  std::string name;  // "01_particles_and_euler.cpp"
  fs::path stub;
};

std::vector<ExerciseFile> kit_exercises(const fs::path& kit) {
  std::ifstream in(kit / "exercises.txt");
  if (!in) throw std::runtime_error((kit / "exercises.txt").string() + " cannot be read");
  std::vector<ExerciseFile> files;
  std::string line;
  while (std::getline(in, line)) {
    const auto tab = line.find('\t');
    if (tab == std::string::npos) continue;
    files.push_back({line.substr(0, tab), fs::path(line.substr(tab + 1))});
  }
  return files;
}

// Where a submission keeps `name`: at its top, or in an exercises/ folder (a copy of the
// starter repository). Empty when it has neither.
fs::path find_in_submission(const fs::path& dir, const std::string& name) {
  for (const fs::path& candidate : {dir / name, dir / "exercises" / name}) {
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec)) return candidate;
  }
  return {};
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  if (from.empty()) return text;
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

}  // namespace

std::string grade_kit_dir() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ((ec ? fs::current_path() : self.parent_path()) / "grade-kit").string();
}

std::string first_build_error(const std::string& log, int max_lines) {
  std::istringstream in(log);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    const bool error = line.find("error:") != std::string::npos ||
                       line.find("undefined reference") != std::string::npos;
    // make's own "*** [...] Error 1" lines follow the real message; they are not it.
    if (!error || line.starts_with("make") || line.starts_with("gmake")) continue;
    std::string text;
    // The compiler names the function first ("x.cpp: In function '...':").
    if (i > 0 && lines[i - 1].find(": In ") != std::string::npos) text = lines[i - 1] + "\n";
    text += line;
    // Then the source line and the caret, indented.
    int taken = 1;
    for (std::size_t j = i + 1; j < lines.size() && taken < max_lines; ++j, ++taken) {
      if (lines[j].empty() || lines[j][0] != ' ') break;
      text += "\n" + lines[j];
    }
    return text;
  }
  return "";
}

SubmissionBuild build_submission(const std::string& submission_dir, const std::string& scratch_dir,
                                 double timeout) {
  const fs::path kit = grade_kit_dir();
  if (!fs::exists(kit / "CMakeLists.txt")) {
    throw std::runtime_error(fmt::format(
        "{} does not exist: build the project first (cmake --build build), so the grader has the "
        "engine and the grading tests to link a submission with",
        (kit / "CMakeLists.txt").string()));
  }
  const fs::path from = submission_dir;
  std::error_code ec;
  if (!fs::is_directory(from, ec))
    throw std::runtime_error("the submission folder " + submission_dir + " does not exist");

  SubmissionBuild result;
  const fs::path scratch = fs::absolute(scratch_dir);
  const fs::path exercises = scratch / "exercises";
  const fs::path build = scratch / "build";
  fs::create_directories(exercises);
  fs::create_directories(build);

  // The submission's files over the stubs, file by file.
  const std::vector<ExerciseFile> files = kit_exercises(kit);
  for (const ExerciseFile& file : files) {
    const fs::path found = find_in_submission(from, file.name);
    if (found.empty()) {
      result.missing.push_back(file.name);
      copy_if_different(file.stub, exercises / file.name);
    } else {
      result.taken.push_back(file.name);
      copy_if_different(found, exercises / file.name);
    }
  }
  for (const fs::path& dir : {from, from / "exercises"}) {
    if (!fs::is_directory(dir, ec)) continue;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const std::string name = entry.path().filename().string();
      const bool known = std::any_of(files.begin(), files.end(),
                                     [&](const ExerciseFile& f) { return f.name == name; });
      if (entry.path().extension() == ".cpp" && !known) result.ignored.push_back(name);
    }
  }

  // A binary left from the submission graded before must never be graded for this one.
  const fs::path binary = build / "grade-submission";
  fs::remove(binary, ec);

  const auto shown = [&](const std::string& text) {
    return replace_all(text, exercises.string() + "/", "exercises/");
  };
  const ProcessResult configure =
      run_process({CLOTHLAB_CMAKE_COMMAND, "-S", kit.string(), "-B", build.string(),
                   "-DCLOTHLAB_EXERCISES=" + exercises.string()},
                  timeout);
  result.log = shown(configure.output);
  if (configure.interrupted) {
    result.first_error = "the grader was interrupted while configuring the build";
    return result;
  }
  if (configure.timed_out || configure.exit_code != 0 || configure.signal != 0) {
    result.first_error = "configuring the submission's build failed:\n" + result.log;
    return result;
  }
  const long jobs = std::max(1L, sysconf(_SC_NPROCESSORS_ONLN));
  const ProcessResult compile = run_process(
      {CLOTHLAB_CMAKE_COMMAND, "--build", build.string(), "--parallel", std::to_string(jobs)},
      timeout);
  result.log += shown(compile.output);
  if (compile.interrupted) {
    result.first_error = "the grader was interrupted while compiling the submission";
  } else if (compile.timed_out) {
    result.first_error = fmt::format("compiling the submission took longer than {:g} s", timeout);
  } else if (compile.exit_code != 0 || compile.signal != 0 || !fs::exists(binary)) {
    result.first_error = first_build_error(shown(compile.output));
    if (result.first_error.empty())
      result.first_error = "the build failed:\n" + shown(compile.output).substr(0, 4000);
  } else {
    result.built = true;
    result.binary = binary.string();
  }
  return result;
}

}  // namespace clothlab::app
