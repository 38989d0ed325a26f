// course.hpp: the course manifest (course.toml at the project's top): its lessons, their
// exercises and points, and the files that make each; and `clothlab course`, which prints it and
// checks that the lessons, the headers and the files agree with it.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace clothlab::app {

struct CourseExercise {
  std::string id;     // "ex02.1"
  std::string title;  // as the lesson's "## Exercise ex02.1: ..." heading has it
  int points = 0;     // the sum of its visible grading cases
  std::vector<std::string> kernels;
  std::string header;  // the engine header that declares the kernels, from the top
};

struct CourseLesson {
  int number = 0;
  std::string title, folder;  // folder from the top: "lessons/02-spring-dampers"
  std::string exercise_file, solution_file, grading_file;  // empty for a lesson without exercises
  std::vector<CourseExercise> exercises;
};

struct Course {
  std::vector<CourseLesson> lessons;

  // The lesson whose exercise this is ("ex02.1" or "ex02"), or null.
  const CourseLesson* lesson_of(const std::string& exercise_id) const;
};

// Reads the manifest at `path`; throws std::runtime_error naming the file, line and column of
// what is wrong, and what was expected.
Course read_course(const std::filesystem::path& path);

// The project's own manifest (CLOTHLAB_SOURCE_DIR/course.toml), read once.
const Course& course();

// What disagrees with the manifest under `root`, one line each ("" when all agree): a file or
// folder it names that is missing, a lesson folder or exercise file it does not name, a lesson's
// "## Exercise" headings other than its exercises (IDs, titles and points, in order), an exercise
// file that does not mention an exercise's ID, a header that does not mark it
// ("// Exercise exNN.k") or does not declare its kernels.
std::vector<std::string> check_course(const Course& course, const std::filesystem::path& root);

void add_course_command(CLI::App& app);

}  // namespace clothlab::app
