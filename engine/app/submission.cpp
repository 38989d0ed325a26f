// submission.cpp: see submission.hpp.
#include "app/submission.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/core.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "app/include_filter.hpp"
#include "app/process.hpp"
#include "app/sandbox.hpp"

namespace clothlab::app {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Writes `text` to a new file at `path`, in place of whatever was there: what was there is
// unlinked, never followed (a symbolic link planted there would have the grader write where it
// points), and the file is made anew (O_EXCL), so that nothing is written through a link that
// appears meanwhile.
void write_new_file(const fs::path& path, const std::string& text) {
  std::error_code ec;
  fs::remove(path, ec);  // a link itself, not what it points to
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) throw std::system_error(errno, std::generic_category(), "creating " + path.string());
  fchmod(fd, 0644);  // whatever the umask: a confined build reads it as another user
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t wrote = write(fd, text.data() + done, text.size() - done);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) {
      const int error = errno;
      close(fd);
      throw std::system_error(error, std::generic_category(), "writing " + path.string());
    }
    done += static_cast<std::size_t>(wrote);
  }
  close(fd);
}

// Puts the exercise file `from` into the scratch folder as `to`, so that the scratch build
// recompiles only the files that changed since it last ran: written only when the contents
// differ, and left out when it is its shipped `stub` as is (the kit links the stub's object,
// which the project's build already compiled).
void take_file(const fs::path& from, const fs::path& to, const fs::path& stub) {
  const std::string text = read_text(from);
  if (text == read_text(stub)) {
    fs::remove(to);
    return;
  }
  if (fs::is_regular_file(fs::symlink_status(to)) && text == read_text(to)) return;
  write_new_file(to, text);
}

constexpr std::uintmax_t kMaxFileBytes = 1 << 20;  // an exercise file is a few kilobytes
// Any file a submission's build writes: an object of an exercise file is well under a megabyte,
// the kernels program a few (a 1 GB object, a large array's zeros spelt out, is refused).
constexpr std::size_t kMaxBuildFileBytes = std::size_t{64} << 20;

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  if (from.empty()) return text;
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

// The build tool's option to go on past a failed file, so that every file that does not compile
// is found in one build.
std::vector<std::string> keep_going_args() {
  const std::string generator = CLOTHLAB_CMAKE_GENERATOR;
  if (generator.find("Ninja") != std::string::npos) return {"--", "-k", "0"};
  if (generator.find("Makefiles") != std::string::npos) return {"--", "-k"};
  return {};
}

// Whether the build log says that compiling `name` (an exercise file) failed: make's
// "*** [.../01_x.cpp.o] Error 1", or ninja's "FAILED: .../01_x.cpp.o".
bool compile_failed(const std::string& log, const std::string& name) {
  const std::string object = "/" + name + ".o";
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    const bool failure =
        (line.find("***") != std::string::npos && line.find("Error") != std::string::npos) ||
        line.starts_with("FAILED:");
    if (failure && line.find(object) != std::string::npos) return true;
  }
  return false;
}

// The linker's complaint about the exercise file `name`, or "": the line that names it as the
// file of code that calls what is defined nowhere, or that defines again what another file
// defines ("03_x.cpp:(.text+0x41): undefined reference to `f()'").
std::string link_error(const std::string& log, const std::string& name) {
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    std::size_t at = line.find("undefined reference to");
    if (at == std::string::npos) at = line.find("multiple definition of");
    if (at == std::string::npos) continue;
    const std::string before = line.substr(0, at);
    if (before.find(name + ":(") != std::string::npos ||
        before.find("/" + name + ".o") != std::string::npos)
      return line;
  }
  return "";
}

}  // namespace

std::string build_dir() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return fs::current_path().string();
  // A student program lives in student-programs/ of the build folder (engine/CMakeLists.txt).
  const fs::path dir = self.parent_path();
  return (dir.filename() == "student-programs" ? dir.parent_path() : dir).string();
}

std::string update_grade_kit(double timeout) {
  std::error_code ec;
  const fs::path build = build_dir();
  // A folder the program was copied to (an autograder's, say) is no build to update.
  if (!fs::exists(build / "CMakeCache.txt", ec)) return "";
  const long jobs = std::max(1L, sysconf(_SC_NPROCESSORS_ONLN));
  const ProcessResult run =
      run_process({CLOTHLAB_CMAKE_COMMAND, "--build", build.string(), "--target", "grade-kit",
                   "--parallel", std::to_string(jobs)},
                  timeout);
  if (run.interrupted) return "interrupted while building the engine and the grading tests";
  if (run.timed_out)
    return fmt::format("building the engine and the grading tests took longer than {:g} s",
                       timeout);
  if (run.exit_code != 0 || run.signal != 0) {
    std::string error = first_build_error(run.output);
    if (error.empty())
      error = run.output.substr(run.output.size() > 4000 ? run.output.size() - 4000 : 0);
    return fmt::format(
        "building the engine and the grading tests ({} --build {} --target "
        "grade-kit) failed:\n{}",
        CLOTHLAB_CMAKE_COMMAND, build.string(), error);
  }
  return "";
}

std::string grade_kit_dir() {
  return (fs::path(build_dir()) / "grade-kit").string();
}

std::string first_build_error(const std::string& log, int max_lines, const std::string& in_file) {
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
    if (!in_file.empty() && !line.starts_with(in_file + ":")) continue;
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

std::vector<KitExercise> kit_exercise_files() {
  const fs::path kit = grade_kit_dir();
  std::ifstream in(kit / "exercises.txt");
  if (!in) throw std::runtime_error((kit / "exercises.txt").string() + " cannot be read");
  std::vector<KitExercise> files;
  std::string line;
  while (std::getline(in, line)) {
    const auto tab = line.find('\t');
    if (tab == std::string::npos) continue;
    files.push_back({line.substr(0, tab), fs::path(line.substr(tab + 1))});
  }
  return files;
}

fs::path find_exercise_file(const fs::path& dir, const std::string& name, std::string& why) {
  std::error_code ec;
  const fs::path root = fs::weakly_canonical(dir, ec);
  for (const fs::path& candidate : {dir / name, dir / "exercises" / name}) {
    const fs::file_status status = fs::symlink_status(candidate, ec);
    if (ec || !fs::exists(status)) continue;
    if (fs::is_symlink(status)) {
      why = name + " (a symbolic link)";
    } else if (!fs::is_regular_file(status)) {
      why = name + " (not a regular file)";
    } else if (!fs::weakly_canonical(candidate, ec).string().starts_with(root.string() + "/")) {
      why = name + " (in a folder that links outside the submission)";
    } else if (fs::file_size(candidate, ec) > kMaxFileBytes) {
      why = name + " (larger than 1 MiB)";
    } else {
      return candidate;
    }
    return {};
  }
  return {};
}

std::vector<std::string> kit_inputs() {
  const fs::path kit = grade_kit_dir();
  std::vector<std::string> inputs{kit.string()};
  std::ifstream in(kit / "inputs.txt");
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) inputs.push_back(line);
  }
  return inputs;
}

namespace {

// `error`, with what a tool stopped by SIGXFSZ does not say itself when `output` shows one was:
// the build wrote past the limit on a file.
std::string said_file_too_large(const std::string& output, const std::string& error) {
  if (output.find("File size limit exceeded") == std::string::npos) return error;
  return fmt::format(
      "the build wrote a file larger than {} MiB (the limit on any file it writes: a large array "
      "with an initial value, say, spelt out in the object file)\n{}",
      kMaxBuildFileBytes >> 20, error);
}

}  // namespace

SubmissionBuild build_submission(const std::string& submission_dir, const std::string& scratch_dir,
                                 double timeout, const Confinement* confinement) {
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
  fs::path scratch = fs::absolute(scratch_dir);
  fs::create_directories(scratch);
  const auto lock = [](const fs::path& dir, bool wait) {
    const int fd = open((dir / ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd >= 0 && flock(fd, wait ? LOCK_EX : LOCK_EX | LOCK_NB) == 0) return fd;
    if (fd >= 0) close(fd);
    return -1;
  };
  int fd = lock(scratch, false);
  bool own_folder = false;
  if (fd < 0) {
    // Another grader builds here: this one takes a folder of its own, so that neither grades
    // the other's binary.
    scratch = scratch.string() + "-" + std::to_string(getpid());
    fs::remove_all(scratch, ec);
    fs::create_directories(scratch);
    fd = lock(scratch, true);
    own_folder = true;
  }
  // A submission (built with a confinement) starts in a fresh folder: nothing an earlier one
  // compiled or changed there (its objects, its CMakeCache.txt, a link planted in exercises/)
  // reaches it, and nothing of it is left once it has been graded. The student's own exercises
  // keep their build, so that only what changed is compiled again.
  const bool fresh = confinement != nullptr;
  const auto clear = [](const fs::path& dir) {
    std::error_code ignored;
    fs::remove_all(dir / "exercises", ignored);
    fs::remove_all(dir / "build", ignored);
  };
  if (fresh) {
    clear(scratch);
    // The folder is the grader's, whoever an older grader had given it to.
    if (geteuid() == 0 && lchown(scratch.c_str(), 0, 0) == 0) chmod(scratch.c_str(), 0755);
  }
  result.hold = std::shared_ptr<void>(nullptr, [fd, scratch, own_folder, fresh, clear](void*) {
    if (fresh) clear(scratch);
    if (fd >= 0) close(fd);
    std::error_code ignored;
    if (own_folder) fs::remove_all(scratch, ignored);
  });
  const fs::path exercises = scratch / "exercises";
  const fs::path build = scratch / "build";
  fs::create_directories(exercises);
  fs::create_directories(build);
  if (fresh) chmod(exercises.c_str(), 0755);

  // The submission's files over the stubs, file by file.
  const std::vector<KitExercise> files = kit_exercise_files();
  for (const KitExercise& file : files) {
    std::string why;
    const fs::path found = find_exercise_file(from, file.name, why);
    if (!why.empty()) result.refused.push_back(why);
    if (found.empty()) {
      if (why.empty()) result.missing.push_back(file.name);
      take_file(file.stub, exercises / file.name, file.stub);
      continue;
    }
    result.taken.push_back(file.name);
    const std::string problem = include_problem(file.name, read_text(found));
    if (problem.empty()) {
      take_file(found, exercises / file.name, file.stub);
    } else {
      result.broken.push_back({file.name, problem});
      take_file(file.stub, exercises / file.name, file.stub);
    }
  }
  for (const fs::path& dir : {from, from / "exercises"}) {
    if (!fs::is_directory(dir, ec)) continue;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const std::string name = entry.path().filename().string();
      const bool known = std::any_of(files.begin(), files.end(),
                                     [&](const KitExercise& f) { return f.name == name; });
      if (entry.path().extension() == ".cpp" && !known) result.ignored.push_back(name);
    }
  }
  // A binary left from the submission graded before must never be graded for this one.
  const fs::path binary = build / "grade-kernels";
  fs::remove(binary, ec);
  // The build alone is the confined user's: the exercise files stay the grader's, who writes them.
  // The student's own build runs unconfined, but in the same minimal environment
  // (Confinement::build), so that the same files get the same compiler's words either way (its
  // quotes, for one, follow LANG).
  if (confinement != nullptr) hand_over(*confinement, build.string());
  const std::vector<std::string> confined =
      (confinement != nullptr ? *confinement : Confinement{}).build(kit_inputs(), scratch.string());

  const auto shown = [&](const std::string& text) {
    return replace_all(text, exercises.string() + "/", "exercises/");
  };
  // Configured once per scratch folder: the build tool configures again by itself when the kit
  // changes, and the exercise files keep their names.
  const fs::path configured = build / "clothlab-configured";
  if (!fs::exists(configured, ec)) {
    std::vector<std::string> args = confined;
    for (const std::string& arg :
         {std::string(CLOTHLAB_CMAKE_COMMAND), std::string("-G"),
          std::string(CLOTHLAB_CMAKE_GENERATOR), std::string("-S"), kit.string(), std::string("-B"),
          build.string(), "-DCLOTHLAB_EXERCISES=" + exercises.string()})
      args.push_back(arg);
    const ProcessResult configure = run_process(args, timeout);
    result.log = shown(configure.output);
    if (configure.interrupted) {
      result.first_error = "the grader was interrupted while configuring the build";
      return result;
    }
    if (configure.timed_out || configure.exit_code != 0 || configure.signal != 0) {
      result.first_error = "configuring the submission's build failed:\n" + result.log;
      return result;
    }
    std::ofstream(configured) << "configured\n";
  }
  const long jobs = std::max(1L, sysconf(_SC_NPROCESSORS_ONLN));
  std::vector<std::string> args = confined;
  for (const std::string& arg : {std::string(CLOTHLAB_CMAKE_COMMAND), std::string("--build"),
                                 build.string(), std::string("--parallel"), std::to_string(jobs)})
    args.push_back(arg);
  for (const std::string& arg : keep_going_args())
    args.push_back(arg);
  // The compiler reads what the submission says: bounded like a case, so that no file it is
  // pointed at can make it take the machine.
  ProcessLimits limits;
  limits.memory_bytes = std::size_t{4} << 30;
  limits.cpu_seconds = timeout;
  limits.file_bytes = kMaxBuildFileBytes;
  ProcessResult compile = run_process(args, timeout, limits);
  result.log += shown(compile.output);

  // A file that does not compile, or that the linker blames, gives way to its stub, and the build
  // is tried again, so that the other exercises are graded on what their files say. (The link is
  // tried only once every file compiles, so a round may blame a file the last one did not.)
  const auto failed = [&] {
    return compile.exit_code != 0 || compile.signal != 0 || !fs::exists(binary, ec);
  };
  while (failed() && !compile.interrupted && !compile.timed_out) {
    bool blamed = false;
    for (const KitExercise& file : files) {
      if (std::any_of(result.broken.begin(), result.broken.end(),
                      [&](const SubmissionBuild::Broken& b) { return b.name == file.name; }))
        continue;
      std::string error;
      if (compile_failed(compile.output, file.name)) {
        error = first_build_error(shown(compile.output), 8, "exercises/" + file.name);
        if (error.empty()) error = first_build_error(shown(compile.output));
      } else {
        error = link_error(compile.output, file.name);
      }
      if (error.empty()) continue;
      result.broken.push_back({file.name, said_file_too_large(error, error)});
      take_file(file.stub, exercises / file.name, file.stub);
      blamed = true;
    }
    if (!blamed) break;
    compile = run_process(args, timeout, limits);
    result.log += shown(compile.output);
  }

  if (compile.interrupted) {
    result.first_error = "the grader was interrupted while compiling the submission";
  } else if (compile.timed_out) {
    result.first_error = fmt::format("compiling the submission took longer than {:g} s", timeout);
  } else if (compile.exit_code != 0 || compile.signal != 0 || !fs::exists(binary, ec)) {
    result.first_error = first_build_error(shown(compile.output));
    if (result.first_error.empty())
      result.first_error = "the build failed:\n" + shown(compile.output).substr(0, 4000);
  } else {
    result.built = true;
    result.binary = binary.string();
  }
  if (!result.built) result.first_error = said_file_too_large(compile.output, result.first_error);
  return result;
}

}  // namespace clothlab::app
