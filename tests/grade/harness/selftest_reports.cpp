// selftest_reports.cpp: test cases whose results a student must not see, and names and messages
// that would break a report, to test the grader's reports (check_reports.py).
//
// Every word a student must not see says SECRET: the cases that are not visible now (Gradescope's
// "after_due_date", "after_published" and "hidden") carry it in their names, hints, messages and
// expected values. The other cases are visible, and hold text that would draw a fake line in a
// report ("Total: 130 / 130 points" after a line break) or that XML 1.0 forbids.
#include <doctest/doctest.h>

#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>

#include "grading.hpp"

namespace {

// Bytes no XML document may hold, and no JSON one as they are: a surrogate (U+D800), two overlong
// forms of '/', a code point past U+10FFFF, U+FFFE and U+FFFF, control characters, a C1 control,
// a lone byte, a sequence cut short, a carriage return and the characters that break or reorder
// lines (U+2028, U+202E).
constexpr const char* kNotXml =
    "surrogate \xed\xa0\x80, overlong \xc0\xaf and \xe0\x80\xaf, past U+10FFFF \xf4\x90\x80\x80, "
    "U+FFFE \xef\xbf\xbe, U+FFFF \xef\xbf\xbf, controls \x01\x0b\x1b[2J, C1 \xc2\x85, lone \xff, "
    "cut \xe2\x82, return \r, separator \xe2\x80\xa8, reversed \xe2\x80\xae";

constexpr const char* kFakeTotal = "\n\nTotal: 130 / 130 points\n";

// Written by a hidden case in the folder the grader runs in.
constexpr const char* kLeftBehind = "left-behind-by-a-hidden-case.txt";

}  // namespace

// One exercise, ex93.1, of visible and hidden cases.
TEST_SUITE("ex93") {
  // visible, passed: 2 points a student sees
  TEST_CASE("ex93.1 a visible case that passes" * POINTS(2)) {
    CHECK(true);
  }

  // visible, failed: shown in full to the student
  TEST_CASE("ex93.1 a visible case that fails" * POINTS(3)) {
    INFO("visible hint: add the damper");
    CHECK(1 == 2);
  }

  // after_due_date, failed: its name, hint and expected value are not shown before the due date
  TEST_CASE("ex93.1 SECRET-NAME-A fails" * POINTS_VISIBILITY(4, after_due_date)) {
    INFO("SECRET-HINT-A");
    CHECK(std::string("computed") == std::string("SECRET-EXPECTED-A"));
  }

  // hidden, failed: never shown. It leaves a file behind, as kernels without a sandbox could, for
  // a case run after it to print.
  TEST_CASE("ex93.1 SECRET-NAME-B throws" * POINTS_VISIBILITY(5, hidden)) {
    std::ofstream(kLeftBehind) << "SECRET-INPUT-B\n";
    throw std::runtime_error("SECRET-MESSAGE-B");
  }

  // after_published, passed: its 6 points are not in the student's table either
  TEST_CASE("ex93.1 SECRET-NAME-C passes" * POINTS_VISIBILITY(6, after_published)) {
    CHECK(true);
  }

}  // TEST_SUITE("ex93")

TEST_SUITE("ex94") {
  // hidden, failed: an exercise whose cases are all hidden has no row in the student's table
  TEST_CASE("ex94.1 SECRET-NAME-D fails" * POINTS_VISIBILITY(7, hidden)) {
    FAIL("SECRET-FAILURE-D");
  }

}  // TEST_SUITE("ex94")

// Each below in an exercise of its own, so that the summary shows its failure in full.
TEST_SUITE("ex95") {
  // visible, failed: an exception's text with line breaks. It prints what a hidden case left
  // behind, were that case run before it.
  TEST_CASE("ex95.1 a message with a fake summary" * POINTS(1)) {
    std::cout << std::ifstream(kLeftBehind).rdbuf() << std::flush;
    throw std::runtime_error(std::string("boom") + kFakeTotal);
  }

}  // TEST_SUITE("ex95")

TEST_SUITE("ex96") {
  // visible, failed: a name with line breaks
  TEST_CASE("ex96.1 a name that breaks the line\n\nTotal: 130 / 130 points" * POINTS(1)) {
    FAIL("named with a line break");
  }

}  // TEST_SUITE("ex96")

TEST_SUITE("ex97") {
  // visible, failed: text XML forbids, in the name, the hint, the values and the output
  TEST_CASE("ex97.1 a name with U+FFFF \xef\xbf\xbf and a surrogate \xed\xa0\x80" * POINTS(1)) {
    std::cout << kNotXml << "\n";
    INFO("a hint" << std::string(kFakeTotal));
    INFO(std::string(kNotXml));
    CHECK(std::string(kNotXml) == std::string("x"));
  }

}  // TEST_SUITE("ex97")

// The file name a failure names, with a line separator (U+2028) and an escape in it. (A line
// feed would do as well, but the assembler warns of it in the debugging information.)
#line 1 "selftest_reports\xe2\x80\xa8Total: 130 / 130 points\x1b[2J.cpp"
TEST_SUITE("ex98") {
  // visible, failed: a failure in a file whose name breaks the line
  TEST_CASE("ex98.1 a failure in a file named with a line separator" * POINTS(1)) {
    CHECK(1 == 2);
  }

}  // TEST_SUITE("ex98")
