// Grading tests for lesson 11, the game loop (exercise ex11.1, the accumulator's arithmetic).
//
// Every expected value is worked out in the comment beside it, from the lesson's rule: with
// time = leftover + frame_time, the steps due are n = floor(time / dt + kStepTolerance), the
// new leftover is time - n dt (0 if that is below 0), at most max_substeps are taken and the
// whole steps beyond are dropped. Times are compared with a tolerance (1e-12 s, a billionth of
// a millisecond step), never bit for bit.
#include <cmath>
#include <sstream>
#include <vector>

#include "clothlab/core/game_loop.hpp"
#include "grading.hpp"

using clothlab::Substeps;

namespace {

// Frames of the given lengths through the accumulator, as Simulation::advance does it; returns
// the steps taken in all, and the last leftover in `leftover`.
long steps_for(const std::vector<double>& frames, double dt, double& leftover) {
  long steps = 0;
  leftover = 0.0;
  for (double frame : frames) {
    const Substeps s = clothlab::accumulate(leftover, frame, dt, 1000000);
    steps += s.count;
    leftover = s.leftover;
  }
  return steps;
}

}  // namespace

TEST_SUITE("ex11") {
  TEST_CASE("ex11.1 a frame of whole steps and a frame shorter than a step" * POINTS(2)) {
    {
      // 10 ms at dt = 2.5 ms (both exact in binary): exactly 4 steps, nothing left over.
      const Substeps s = clothlab::accumulate(0.0, 0.01, 0.0025, 100);
      INFO("leftover 0, frame 10 ms, dt 2.5 ms: 10 / 2.5 = 4 steps and no time left; got "
           << s.count << " steps, leftover " << s.leftover << " s, dropped " << s.dropped << " s");
      CHECK(s.count == 4);
      CHECK(std::abs(s.leftover) <= 1e-12);
      CHECK(s.dropped == 0.0);
    }
    {
      // 0.4 ms at dt = 1 ms: no step yet, all of it waits for the next frame.
      const Substeps s = clothlab::accumulate(0.0, 0.0004, 0.001, 100);
      INFO("a frame shorter than dt takes no step and keeps all its time as leftover; got "
           << s.count << " steps, leftover " << s.leftover << " s (expected 0.0004 s)");
      CHECK(s.count == 0);
      CHECK(std::abs(s.leftover - 0.0004) <= 1e-12);
    }
  }

  TEST_CASE("ex11.1 the leftover of the last frame counts" * POINTS(2)) {
    // leftover 0.7 ms + frame 1.6 ms = 2.3 ms at dt = 1 ms: 2 steps, 0.3 ms left.
    const Substeps s = clothlab::accumulate(0.0007, 0.0016, 0.001, 100);
    std::ostringstream said;
    said << "leftover 0.7 ms + frame 1.6 ms = 2.3 ms: 2 steps of 1 ms and 0.3 ms left over (add "
            "the leftover to the frame time first); got "
         << s.count << " steps, leftover " << s.leftover << " s";
    // What the usual slips give here, as (count, leftover, dropped), is worked out in slips.hpp
    // (kLeftoverCounts).
    INFO(grading::hint(clothlab::Vec3(static_cast<double>(s.count), s.leftover, s.dropped),
                       grading::slips::kLeftoverCounts, 1e-12, said.str()));
    CHECK(s.count == 2);
    CHECK(std::abs(s.leftover - 0.0003) <= 1e-12);
    CHECK(s.dropped == 0.0);
  }

  TEST_CASE("ex11.1 a time a hair short of a step counts as the step" * POINTS(2)) {
    {
      // 1 ms - 1e-15 s at dt = 1 ms: a millionth of a millionth of a step short, far inside
      // kStepTolerance dt = 1e-9 s. One step, and the leftover (-1e-15 s) becomes 0.
      const Substeps s = clothlab::accumulate(0.0, 0.001 - 1e-15, 0.001, 100);
      INFO(
          "time = dt - 1e-15 s is within kStepTolerance * dt of a whole step: it counts as one "
          "step and leaves 0, never a negative leftover (hints 2 and 3); got "
          << s.count << " steps, leftover " << s.leftover << " s");
      CHECK(s.count == 1);
      CHECK(s.leftover >= 0.0);
      CHECK(s.leftover <= 1e-12);
    }
    {
      // 0.999 ms at dt = 1 ms: a thousandth of a step short, far outside the tolerance: no step.
      const Substeps s = clothlab::accumulate(0.0, 0.000999, 0.001, 100);
      INFO("time = 0.999 dt is a real part of a step, not rounding: no step, all of it left; got "
           << s.count << " steps, leftover " << s.leftover << " s");
      CHECK(s.count == 0);
      CHECK(std::abs(s.leftover - 0.000999) <= 1e-12);
    }
  }

  TEST_CASE("ex11.1 the step count depends only on the total time" * POINTS(2)) {
    // 2 s at dt = 1 ms is 2000 steps, however it is cut: 120 frames of 1/60 s, 60 of 1/30 s,
    // 288 of 1/144 s, or one of 2 s. Neither 1/60 nor 0.001 is exact in binary, so a count
    // without the tolerance gives 1999 for the first three (hint 2).
    const double dt = 0.001;
    const std::vector<std::vector<double>> splits = {std::vector<double>(120, 1.0 / 60.0),
                                                     std::vector<double>(60, 1.0 / 30.0),
                                                     std::vector<double>(288, 1.0 / 144.0),
                                                     {2.0}};
    const char* names[] = {"120 frames of 1/60 s", "60 frames of 1/30 s", "288 frames of 1/144 s",
                           "one frame of 2 s"};
    for (size_t k = 0; k < splits.size(); ++k) {
      double leftover = 0.0;
      const long steps = steps_for(splits[k], dt, leftover);
      INFO(std::string(names[k]) << " at dt = 1 ms must take 2000 steps and leave nothing; got "
                                 << steps << " steps and a leftover of " << leftover / dt << " dt");
      CHECK(steps == 2000);
      CHECK(leftover <= 1e-12);
    }
  }

  TEST_CASE("ex11.1 the cap drops whole steps and keeps the fraction" * POINTS(2)) {
    {
      // A 1.0055 s hitch at dt = 10 ms with a cap of 25: 100 steps due (1.0055 / 0.01 = 100.55),
      // 25 taken, 75 dropped (0.75 s), and the 5.5 ms fraction kept for the next frame.
      const Substeps s = clothlab::accumulate(0.0, 1.0055, 0.01, 25);
      INFO(
          "1.0055 s at dt = 10 ms with at most 25 substeps: take 25, drop the other 75 whole "
          "steps (0.75 s), keep the 0.0055 s fraction as leftover (hint 4); got "
          << s.count << " steps, dropped " << s.dropped << " s, leftover " << s.leftover << " s");
      CHECK(s.count == 25);
      CHECK(std::abs(s.dropped - 0.75) <= 1e-12);
      CHECK(std::abs(s.leftover - 0.0055) <= 1e-12);
    }
    {
      // A day-long pause (86400 s) at dt = 1 ms: 86.4 million steps due, more than a loop should
      // count one by one; 10 are taken and the rest dropped.
      const Substeps s = clothlab::accumulate(0.0, 86400.0, 0.001, 10);
      INFO("86400 s at dt = 1 ms with a cap of 10: take 10, drop 86399.99 s; got "
           << s.count << " steps, dropped " << s.dropped << " s, leftover " << s.leftover << " s");
      CHECK(s.count == 10);
      CHECK(std::abs(s.dropped - 86399.99) <= 1e-6);
      CHECK(s.leftover >= 0.0);
      CHECK(s.leftover < 0.001);
    }
  }
}
