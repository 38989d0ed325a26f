// exercises.cpp: exercise IDs and the lessons they belong to (exercises.hpp).
#include "app/grade/exercises.hpp"

#include <algorithm>
#include <filesystem>
#include <system_error>

namespace clothlab::app::grading {

namespace fs = std::filesystem;

// An exercise ID: "ex01.3", or with lesson_only "ex01". (Parsed by hand: g++ 12 warns inside
// <regex> when built with the sanitizers.)
bool is_exercise_id(std::string_view id, bool lesson_only) {
  auto digits = [](std::string_view d) {
    return !d.empty() &&
           std::all_of(d.begin(), d.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (!id.starts_with("ex")) return false;
  const auto dot = id.find('.');
  if (dot == std::string_view::npos) return lesson_only && digits(id.substr(2));
  return digits(id.substr(2, dot - 2)) && digits(id.substr(dot + 1));
}

// "ex01.3 explicit Euler ..." -> "ex01.3"; a case without an ID counts under its suite.
std::string exercise_of(const std::string& name, const std::string& suite) {
  const std::string first_word = name.substr(0, name.find_first_of(" \t"));
  if (is_exercise_id(first_word, false)) return first_word;
  return suite.empty() ? "(no exercise)" : suite;
}

// "ex01.3" -> "1.3", as the lessons number their exercises.
std::string number_of(const std::string& exercise) {
  if (!is_exercise_id(exercise, true)) return exercise;
  const auto dot = exercise.find('.');
  const std::string part = dot == std::string::npos ? "" : exercise.substr(dot);
  return std::to_string(std::stoi(exercise.substr(2, dot - 2))) + part;
}

// "see lessons/01-particles-and-euler/README.md, Exercise ex01.3"
std::string lesson_hint(const std::string& exercise) {
  if (!is_exercise_id(exercise, true)) return "";
  const std::string prefix = exercise.substr(2, exercise.find('.') - 2) + "-";  // "01-"
  std::string lesson = "lessons/" + prefix + "*/README.md";
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(fs::path(CLOTHLAB_SOURCE_DIR) / "lessons", ec)) {
    const std::string folder = entry.path().filename().string();
    if (entry.is_directory() && folder.starts_with(prefix)) {
      lesson = "lessons/" + folder + "/README.md";
    }
  }
  return "see " + lesson + ", Exercise " + exercise;
}

}  // namespace clothlab::app::grading
