// not_implemented.hpp: what an exercise stub throws until the student fills it in.
//
// A stub never returns a quiet zero (the cloth would just sit there and nobody would know why);
// it throws, naming the exercise and the lesson that explains it.
#pragma once

#include <stdexcept>
#include <string>

namespace clothlab {

class NotImplemented : public std::logic_error {
 public:
  NotImplemented(const std::string& exercise, const std::string& lesson)
      : std::logic_error("exercise " + exercise + " is not implemented yet: see " + lesson +
                         " and fill in the marked region in exercises/"),
        exercise_(exercise),
        lesson_(lesson) {}
  const std::string& exercise() const { return exercise_; }
  const std::string& lesson() const { return lesson_; }

 private:
  std::string exercise_;
  std::string lesson_;
};

}  // namespace clothlab

// The one line a shipped stub holds inside its marked region.
#define CLOTHLAB_TODO(exercise, lesson) throw ::clothlab::NotImplemented(exercise, lesson)
