// exercises.hpp: exercise IDs as the course spells them ("ex01.3"), and the lesson that
// teaches each.
#pragma once

#include <string>
#include <string_view>

namespace clothlab::app::grading {

// An exercise ID: "ex01.3", or with lesson_only "ex01".
bool is_exercise_id(std::string_view id, bool lesson_only);

// "ex01.3 explicit Euler ..." -> "ex01.3"; a case without an ID counts under its suite.
std::string exercise_of(const std::string& name, const std::string& suite);

// "ex01.3" -> "1.3", as the lessons number their exercises.
std::string number_of(const std::string& exercise);

// "see lessons/01-particles-and-euler/README.md, Exercise ex01.3"; "" for no exercise ID.
std::string lesson_hint(const std::string& exercise);

}  // namespace clothlab::app::grading
