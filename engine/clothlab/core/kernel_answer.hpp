// kernel_answer.hpp: an exercise's answer that the engine cannot use.
//
// Most exercise kernels return numbers, and a wrong number makes a wrong cloth, which the guard
// and the lesson's scenes show. Three return indices that the engine then reads or writes at:
// bending_pairs (ex04.1) particles, select_tears (ex06.2) springs, cell_hash (ex10.1) slots of a
// table. An index out of range there would read or write outside an array: a crash, or worse, a
// run that goes on with corrupted memory. So the engine checks each such answer before it uses
// it (one comparison an index) and throws this instead, naming the exercise, the answer and the
// range it had to be in. Thrown during a step of `clothlab run`, it stops the run as a blow-up
// does (engine/io/run.cpp): with the step, and the frames before it.
#pragma once

#include <stdexcept>
#include <string>

namespace clothlab {

class KernelAnswerError : public std::runtime_error {
 public:
  KernelAnswerError(const std::string& exercise, const std::string& what)
      : std::runtime_error(what + " (exercise " + exercise + ")"), exercise_(exercise) {}
  const std::string& exercise() const { return exercise_; }

 private:
  std::string exercise_;
};

}  // namespace clothlab
