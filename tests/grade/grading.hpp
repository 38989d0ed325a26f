// grading.hpp: what every grading file includes.
//
// A grading test case belongs to one exercise and carries points:
//
//   TEST_SUITE("ex01") {
//   TEST_CASE("ex01.1 gravity pulls down with m g" * POINTS(2)) { ... }
//   }
//
// The case name starts with the exercise ID; POINTS(n) is how many points it is worth. Case
// names must not contain commas, '*' or '?' (doctest reads those as filter syntax).
//
// Hidden tests (tests/grade-hidden/, which the student release leaves out) are reported to
// Gradescope as "after_due_date" unless a case says otherwise with
// POINTS_VISIBILITY(n, hidden) (or visible, after_published, after_due_date).
// Expectations are derived in a comment beside each check, and a grading test never calls
// the solutions: it must hold for any correct answer.
#pragma once

#include <doctest/doctest.h>

#include <sstream>
#include <string>

#include "clothlab/core/types.hpp"
#include "slips.hpp"

#define POINTS(n) doctest::description("points=" #n)
#define POINTS_VISIBILITY(n, visibility) \
  doctest::description("points=" #n " visibility=" #visibility)

namespace doctest {
// Prints a Vec3 as (x, y, z) in a failed check, so the message shows the numbers.
template <>
struct StringMaker<clothlab::Vec3> {
  static String convert(const clothlab::Vec3& a) {
    std::ostringstream out;
    out.precision(10);
    out << "(" << a.x() << ", " << a.y() << ", " << a.z() << ")";
    return out.str().c_str();
  }
};
}  // namespace doctest

namespace grading {

// True when |a - b| <= tol in every component (and both are finite).
inline bool near(const clothlab::Vec3& a, const clothlab::Vec3& b, double tol) {
  return ((a - b).cwiseAbs().array() <= tol).all();
}

// "(x, y, z)" with enough digits to tell two answers apart.
inline std::string show(const clothlab::Vec3& a) {
  return doctest::StringMaker<clothlab::Vec3>::convert(a).c_str();
}

}  // namespace grading

// Checks that two Vec3 agree within tol, and on failure prints both: "got (..), expected (..)".
#define CHECK_NEAR_VEC(actual, expected, tol)                                                   \
  CHECK_MESSAGE(::grading::near((actual), (expected), (tol)),                                   \
                "got " << ::grading::show(actual) << ", expected " << ::grading::show(expected) \
                       << " (to within " << (tol) << ")")
