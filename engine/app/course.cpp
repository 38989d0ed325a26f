#include "app/course.hpp"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <toml++/toml.h>
#include <CLI/CLI.hpp>

#include "app/exit_codes.hpp"

namespace clothlab::app {

namespace fs = std::filesystem;

namespace {

// "course.toml:12:3: error: ..." for the node `at`.
[[noreturn]] void fail_at(const std::string& file, const toml::source_region& at,
                          const std::string& what) {
  throw std::runtime_error(
      fmt::format("{}:{}:{}: error: {}", file, at.begin.line, at.begin.column, what));
}

std::string required_string(const std::string& file, const toml::table& t, const char* key) {
  const auto* value = t.get_as<std::string>(key);
  if (!value) fail_at(file, t.source(), fmt::format("expected a string '{}'", key));
  return value->get();
}

std::string optional_string(const std::string& file, const toml::table& t, const char* key) {
  const toml::node* node = t.get(key);
  if (!node) return "";
  if (!node->is_string()) fail_at(file, node->source(), fmt::format("'{}' must be a string", key));
  return node->as_string()->get();
}

long required_integer(const std::string& file, const toml::table& t, const char* key, long low,
                      long high) {
  const auto* value = t.get_as<int64_t>(key);
  if (!value || value->get() < low || value->get() > high) {
    fail_at(file, value ? value->source() : t.source(),
            fmt::format("expected '{}', an integer from {} to {}", key, low, high));
  }
  return static_cast<long>(value->get());
}

CourseExercise read_exercise(const std::string& file, const toml::node& node, int lesson) {
  const toml::table* t = node.as_table();
  if (!t) fail_at(file, node.source(), "expected an exercise { id = ..., title = ..., ... }");
  CourseExercise e;
  e.id = required_string(file, *t, "id");
  const std::string prefix = fmt::format("ex{:02}.", lesson);
  const std::string part = e.id.substr(std::min(e.id.size(), prefix.size()));
  const bool number =
      !part.empty() && part[0] != '0' &&
      std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!e.id.starts_with(prefix) || !number) {
    fail_at(file, t->get("id")->source(),
            fmt::format("exercise id '{}'; expected {}K, K = 1, 2, ...", e.id, prefix));
  }
  e.title = required_string(file, *t, "title");
  e.points = static_cast<int>(required_integer(file, *t, "points", 1, 1000));
  e.header = required_string(file, *t, "header");
  const toml::array* kernels = t->get_as<toml::array>("kernels");
  if (!kernels || kernels->empty()) {
    fail_at(file, t->source(), "expected 'kernels', a list of the functions the student writes");
  }
  for (const toml::node& k : *kernels) {
    if (!k.is_string()) fail_at(file, k.source(), "a kernel is named by a string");
    e.kernels.push_back(k.as_string()->get());
  }
  return e;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

const CourseLesson* Course::lesson_of(const std::string& exercise_id) const {
  if (exercise_id.size() < 4 || !exercise_id.starts_with("ex")) return nullptr;
  int number = 0;
  for (size_t k = 2; k < exercise_id.size() && exercise_id[k] != '.'; ++k) {
    if (exercise_id[k] < '0' || exercise_id[k] > '9') return nullptr;
    number = 10 * number + (exercise_id[k] - '0');
    if (number > 99) return nullptr;
  }
  for (const CourseLesson& lesson : lessons)
    if (lesson.number == number) return &lesson;
  return nullptr;
}

Course read_course(const fs::path& path) {
  const std::string file = path.string();
  toml::table root;
  try {
    root = toml::parse_file(file);
  } catch (const toml::parse_error& error) {
    fail_at(file, error.source(), std::string(error.description()));
  }
  const toml::array* lessons = root.get_as<toml::array>("lesson");
  if (!lessons || lessons->empty()) {
    throw std::runtime_error(file + ":1:1: error: expected [[lesson]] tables");
  }
  Course course;
  std::set<long> numbers;
  for (const toml::node& node : *lessons) {
    const toml::table& t = *node.as_table();
    CourseLesson lesson;
    lesson.number = static_cast<int>(required_integer(file, t, "number", 1, 99));
    if (!numbers.insert(lesson.number).second) {
      fail_at(file, t.get("number")->source(),
              fmt::format("lesson {} is listed twice", lesson.number));
    }
    lesson.title = required_string(file, t, "title");
    lesson.folder = required_string(file, t, "folder");
    lesson.exercise_file = optional_string(file, t, "exercise_file");
    lesson.solution_file = optional_string(file, t, "solution_file");
    lesson.grading_file = optional_string(file, t, "grading_file");
    if (const toml::node* exercises = t.get("exercises")) {
      if (!exercises->is_array()) fail_at(file, exercises->source(), "expected a list exercises");
      for (const toml::node& e : *exercises->as_array())
        lesson.exercises.push_back(read_exercise(file, e, lesson.number));
    }
    const bool has_files = !lesson.exercise_file.empty() && !lesson.solution_file.empty() &&
                           !lesson.grading_file.empty();
    if (lesson.exercises.empty() != lesson.exercise_file.empty() ||
        (!lesson.exercises.empty() && !has_files)) {
      fail_at(file, t.source(),
              "a lesson with exercises names exercise_file, solution_file and grading_file, "
              "and a lesson without names none");
    }
    course.lessons.push_back(std::move(lesson));
  }
  return course;
}

const Course& course() {
  static const Course manifest = read_course(fs::path(CLOTHLAB_SOURCE_DIR) / "course.toml");
  return manifest;
}

std::vector<std::string> check_course(const Course& course, const fs::path& root) {
  std::vector<std::string> problems;
  const bool solutions = fs::exists(root / "solutions");  // a student release has none
  const auto need = [&](const std::string& path, const std::string& what) {
    if (!path.empty() && !fs::exists(root / path))
      problems.push_back(fmt::format("{} {} is missing", what, path));
  };
  std::set<std::string> folders, exercise_files;
  for (const CourseLesson& lesson : course.lessons) {
    folders.insert(lesson.folder);
    exercise_files.insert(lesson.exercise_file);
    need(lesson.folder + "/README.md", fmt::format("lesson {}'s", lesson.number));
    need(lesson.exercise_file, "the exercise file");
    need(lesson.grading_file, "the grading file");
    if (solutions) need(lesson.solution_file, "the solution file");
    // The lesson's headings, in order, "## Exercise ex02.1: the spring-damper force (6 points)",
    // against what the manifest says they are.
    std::vector<std::string> said, listed;
    std::istringstream readme(read_text(root / lesson.folder / "README.md"));
    for (std::string line; std::getline(readme, line);) {
      if (line.starts_with("## Exercise ")) said.push_back(line.substr(12));
    }
    for (const CourseExercise& e : lesson.exercises) {
      listed.push_back(
          fmt::format("{}: {} ({} point{})", e.id, e.title, e.points, e.points == 1 ? "" : "s"));
    }
    if (said != listed) {
      problems.push_back(
          fmt::format("{}/README.md has the exercise headings [{}]; course.toml lists [{}]",
                      lesson.folder, fmt::join(said, "; "), fmt::join(listed, "; ")));
    }
    const std::string student =
        lesson.exercise_file.empty() ? "" : read_text(root / lesson.exercise_file);
    for (const CourseExercise& e : lesson.exercises) {
      if (!student.empty() && student.find("Exercise " + e.id) == std::string::npos)
        problems.push_back(
            fmt::format("{} does not mention Exercise {}", lesson.exercise_file, e.id));
      need(e.header, fmt::format("{}'s header", e.id));
      const std::string header = read_text(root / e.header);
      if (!header.empty() && header.find("// Exercise " + e.id) == std::string::npos)
        problems.push_back(fmt::format("{} does not mark // Exercise {}", e.header, e.id));
      for (const std::string& kernel : e.kernels) {
        if (!header.empty() && header.find(" " + kernel + "(") == std::string::npos)
          problems.push_back(
              fmt::format("{} does not declare {}'s kernel {}", e.header, e.id, kernel));
      }
    }
  }
  // Whatever is on disk and not in the manifest.
  for (const char* dir : {"lessons", "exercises"}) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(root / dir, ec)) {
      const std::string name = entry.path().filename().string();
      if (name.size() < 3 || name[0] < '0' || name[0] > '9' || name[1] < '0' || name[1] > '9')
        continue;
      const std::string path = std::string(dir) + "/" + name;
      const bool known = std::string(dir) == "lessons" ? folders.count(path) != 0
                                                       : exercise_files.count(path) != 0;
      if (!known) problems.push_back(fmt::format("{} is not in course.toml", path));
    }
  }
  return problems;
}

void add_course_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "course", "Print the course (course.toml): its lessons, exercises, points and files");
  static bool check = false;
  static std::string manifest;
  cmd->add_flag("--check", check,
                "Check that the lessons, headers and files agree with course.toml (exit 1 if not)");
  cmd->add_option("--manifest", manifest, "Read this manifest instead of the project's")
      ->group("");  // for the tests
  cmd->callback([] {
    const fs::path root = CLOTHLAB_SOURCE_DIR;
    Course other;
    if (!manifest.empty()) {
      try {
        other = read_course(manifest);
      } catch (const std::runtime_error& error) {
        fmt::print(stderr, "{}\n", error.what());
        throw CLI::RuntimeError(kExitBadInput);
      }
    }
    const Course& c = manifest.empty() ? course() : other;
    int total = 0;
    for (const CourseLesson& lesson : c.lessons) {
      fmt::print("{:02} {:<34} {}\n", lesson.number, lesson.title, lesson.folder);
      for (const CourseExercise& e : lesson.exercises) {
        fmt::print("   {:<7} {:<44} {:>2} points  {}  ({})\n", e.id, e.title, e.points,
                   fmt::join(e.kernels, ", "), e.header);
        total += e.points;
      }
    }
    fmt::print("{} lessons, {} points\n", c.lessons.size(), total);
    if (!check) return;
    const std::vector<std::string> problems = check_course(c, root);
    for (const std::string& p : problems)
      fmt::print(stderr, "course.toml: {}\n", p);
    if (!problems.empty()) throw CLI::RuntimeError(kExitFailed);
    fmt::print("every lesson, exercise, header and file agrees with course.toml\n");
  });
}

}  // namespace clothlab::app
