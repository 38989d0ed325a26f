// selftest_cases.cpp: test cases that misbehave on purpose, to test the grader itself.
//
// check_grader.cmake grades this binary and checks that each case gets the status and points
// written beside it, and that a crash or a hang costs only its own case.
#include <doctest/doctest.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>

#include "clothlab/core/not_implemented.hpp"
#include "grading.hpp"

TEST_SUITE("ex90") {
  // passed, 2 of 2 points
  TEST_CASE("ex90.1 passes" * POINTS(2)) {
    CHECK(1 + 1 == 2);
  }

  // failed; the failure shows the values and the INFO hint (with characters XML must escape), and
  // what it printed (with bytes that are not UTF-8, which the reports show as "?")
  TEST_CASE("ex90.2 fails with a hint" * POINTS(3)) {
    std::cout << "printed by ex90.2 \xff\xc3(\n";
    const int answer = 1;
    INFO("hint: the answer is 2 & 1 < 2");
    CHECK(answer == 2);
  }

  // crashed: SIGSEGV
  TEST_CASE("ex90.3 crashes with SIGSEGV" * POINTS(1)) {
    std::raise(SIGSEGV);
  }

  // crashed: SIGABRT
  TEST_CASE("ex90.4 aborts" * POINTS(1)) {
    std::abort();
  }

  // timed out after 2 s (the grader's --timeout)
  TEST_CASE("ex90.5 hangs forever" * POINTS(1)) {
    for (;;)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }

  // failed: threw an exception
  TEST_CASE("ex90.6 throws" * POINTS(1)) {
    throw std::runtime_error("boom");
  }

  // not started: the stub's exception names this very exercise
  TEST_CASE("ex90.7 is not started" * POINTS(2)) {
    throw clothlab::NotImplemented("ex90.7", "lessons/90-selftest/README.md");
  }

  // exited with code 3 before reporting a result
  TEST_CASE("ex90.8 exits without reporting" * POINTS(1)) {
    std::_Exit(3);
  }

  // failed: it uses exercise ex90.7, which is not started
  TEST_CASE("ex90.9 needs another exercise" * POINTS(1)) {
    CHECK(std::string("x") == []() -> std::string {
      throw clothlab::NotImplemented("ex90.7", "lessons/90-selftest/README.md");
    }());
  }

  // failed: what a case prints is never read as a verdict, however much it looks like one (the
  // reporter's lines reach the grader through a pipe of their own)
  TEST_CASE("ex90.10 prints a pass and fails" * POINTS(1)) {
    const char fake[] = "@clothlab\tend\tpassed\t0\n";
    std::fputs(fake, stdout);
    std::fputs(fake, stderr);
    std::fflush(nullptr);
    CHECK(1 == 2);
  }

}  // TEST_SUITE("ex90")

TEST_SUITE("ex91") {
  // passed: the crashes and the hang above cost nothing here
  TEST_CASE("ex91.1 passes after the crashes" * POINTS(2)) {
    CHECK(true);
  }

  // passed: doctest reads * and ? as wildcards, which the grader must still match exactly
  TEST_CASE("ex91.2 names with * and ? still run" * POINTS(1)) {
    CHECK(true);
  }

}  // TEST_SUITE("ex91")

TEST_SUITE("ex92") {
  // failed: no test case ran. The grader lists the cases first (with --list-test-cases), then runs
  // each by name; this case exists only while listing, so the run finds nothing to run, and
  // "nothing ran" must never count as a pass.
  bool listing() {
    std::ifstream in("/proc/self/cmdline");
    std::string arg;
    while (std::getline(in, arg, '\0')) {
      if (arg == "--list-test-cases") return true;
    }
    return false;
  }
  void listed_but_never_runs() {}
  const int registered =
      listing()
          ? doctest::detail::regTest(
                doctest::detail::TestCase(listed_but_never_runs, __FILE__, __LINE__,
                                          doctest_detail_test_suite_ns::getCurrentTestSuite()) *
                "ex92.1 is listed but never runs" * POINTS(1))
          : 0;

}  // TEST_SUITE("ex92")
