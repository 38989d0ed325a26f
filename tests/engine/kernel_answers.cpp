// What the engine checks of an exercise's answer before it reads or writes at the indices the
// answer names (clothlab/core/kernel_answer.hpp): bending_pairs' particles, select_tears'
// springs, cell_hash's slots. A bad answer is an error that names the exercise, the answer and
// the range it had to be in, never a read or a write outside an array. (How a run stops on one:
// run.cpp.)
#include <doctest/doctest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "clothlab/after_step/spatial_hash.hpp"
#include "clothlab/after_step/tearing.hpp"
#include "clothlab/core/kernel_answer.hpp"
#include "clothlab/forces/bending.hpp"
using clothlab::IndexPair;
using clothlab::KernelAnswerError;

namespace {

// The message `check` throws, or "" if it throws nothing; the exercise it names goes to `exercise`.
template <class F>
std::string thrown(F&& check, std::string* exercise = nullptr) {
  try {
    check();
  } catch (const KernelAnswerError& e) {
    if (exercise) *exercise = e.exercise();
    return e.what();
  }
  return "";
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("kernel answers: bending pairs must join two particles of the grid") {
  // A 3 x 4 grid has particles 0 to 11.
  CHECK(thrown([] { clothlab::check_bending_pairs(clothlab::bending_pairs(3, 4), 3, 4); }) == "");
  CHECK(thrown([] { clothlab::check_bending_pairs({}, 3, 4); }) == "");
  std::string exercise;
  // Row pairs (r, c)-(r, c + 2) taken up to c = cols - 1: the last one runs past the grid.
  const std::string past = thrown(
      [] {
        clothlab::check_bending_pairs(std::vector<IndexPair>{{0, 2}, {10, 12}}, 3, 4);
      },
      &exercise);
  CHECK(exercise == "ex04.1");
  CHECK(has(past, "bending_pairs(3, 4) returned the pair (10, 12)"));
  CHECK(has(past, "12 is not a particle of a 3 x 4 grid, whose particles are 0 to 11"));
  CHECK(has(thrown([] {
              clothlab::check_bending_pairs(std::vector<IndexPair>{{-1, 1}}, 3, 4);
            }),
            "-1 is not a particle"));
  CHECK(has(thrown([] {
              clothlab::check_bending_pairs(std::vector<IndexPair>{{5, 5}}, 3, 4);
            }),
            "the pair (5, 5): a spring from a particle to itself"));
  // The bending springs of a cloth are built only from pairs that pass.
  const clothlab::Matrix3X x = clothlab::Matrix3X::Zero(3, 12);
  CHECK(clothlab::bending_springs({0, 3, 4}, 1.0, 0.0, x).size() ==
        clothlab::bending_pairs(3, 4).size());
}

TEST_CASE("kernel answers: the springs to tear must be springs of the cloth") {
  CHECK(thrown([] { clothlab::check_tears({0, 4, 9}, 10); }) == "");
  CHECK(thrown([] { clothlab::check_tears({}, 0); }) == "");
  std::string exercise;
  const std::string past = thrown([] { clothlab::check_tears({3, 10}, 10); }, &exercise);
  CHECK(exercise == "ex06.2");
  CHECK(has(past,
            "select_tears returned the position 10, but there are 10 springs, at "
            "positions 0 to 9"));
  // size_t(-1): a negative position made unsigned.
  CHECK(has(thrown([] { clothlab::check_tears({static_cast<size_t>(-1)}, 10); }),
            "a negative number turned into a size_t"));
}

TEST_CASE("kernel answers: a cell's slot must be one of the table's") {
  const clothlab::Cell cell{-1, 2, 3};
  CHECK(clothlab::checked_cell_hash(cell, 7) == clothlab::cell_hash(cell, 7));
  std::string exercise;
  const std::string past = thrown([&] { clothlab::throw_slot_outside(cell, 7, 7); }, &exercise);
  CHECK(exercise == "ex10.1");
  CHECK(has(past,
            "cell_hash(cell (-1, 2, 3), 7) returned the slot 7, but a table of 7 slots "
            "has slots 0 to 6"));
  CHECK_FALSE(has(past, "signed"));
  // -93 computed on signed integers, returned as a size_t (the lesson's example).
  const std::string negative = thrown([&] {
    clothlab::throw_slot_outside(cell, 1000, static_cast<std::size_t>(std::int64_t{-93}));
  });
  CHECK(has(negative, "(-93 as a signed number: compute on std::uint64_t"));
}
