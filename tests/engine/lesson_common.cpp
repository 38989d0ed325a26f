// What every lesson program shares (lessons/common/lesson.hpp): its exit status is clothlab's.
#include <doctest/doctest.h>

#include <stdexcept>

#include "app/exit_codes.hpp"
#include "common/lesson.hpp"

static_assert(int{clothlab::lesson::kExitOk} == int{clothlab::app::kExitOk});
static_assert(int{clothlab::lesson::kExitFailed} == int{clothlab::app::kExitFailed});
static_assert(int{clothlab::lesson::kExitNotDone} == int{clothlab::app::kExitNotDone});

TEST_CASE("lesson programs: a stub exits 4 and an error 1, as clothlab does") {
  CHECK(clothlab::lesson::run("test", [] {}) == clothlab::app::kExitOk);
  CHECK(clothlab::lesson::run("test", [] { return 7; }) == 7);
  CHECK(clothlab::lesson::run("test", [] { throw clothlab::NotImplemented("ex01.1", "01"); }) ==
        clothlab::app::kExitNotDone);
  CHECK(clothlab::lesson::run("test", [] { throw std::runtime_error("no"); }) ==
        clothlab::app::kExitFailed);
}
