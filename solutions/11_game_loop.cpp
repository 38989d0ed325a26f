// Lesson 11, the game loop: the exercise kernel.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`, and
// watch a cloth driven frame by frame through your accumulator with
//   ./build/lesson11-student
// Every symbol is explained in lessons/11-game-loop/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include <algorithm>
#include <cmath>

#include "clothlab/core/game_loop.hpp"
#include "clothlab/core/not_implemented.hpp"

namespace clothlab {

// Exercise ex11.1: the accumulator's arithmetic for one frame (see game_loop.hpp).
//   time = leftover + frame_time                  what the accumulator holds [s]
//   n    = floor(time / dt + kStepTolerance)      whole steps due; a time a hair short of a
//                                                 step counts as the step
//   leftover' = time - n dt, and 0 if that came out below 0 (by at most kStepTolerance dt)
//   count = min(n, max_substeps),  dropped = (n - count) dt
// Hints:
//   1. Count steps with a division and std::floor, not a loop that subtracts dt: a frame after
//      a long pause can hold millions of steps.
//   2. Without kStepTolerance, 120 frames of 1/60 s at dt = 1 ms take 1999 steps, not 2000: the
//      last leftover comes out as 0.9999999999999 dt, because neither 1/60 nor 0.001 is exact
//      in binary. One frame of 2 s takes 2000; the count would depend on the frame times.
//   3. The leftover must be in [0, dt): never negative (rendering would extrapolate backwards),
//      never a whole step.
//   4. The cap drops whole steps only: the fraction of a step in the leftover is kept, so
//      alpha stays right.
Substeps accumulate(double leftover, double frame_time, double dt, long max_substeps) {
  // BEGIN ex11.1: see lessons/11-game-loop/README.md
  const double time = leftover + frame_time;  // [s]
  // The steps in `time`, a time within the tolerance short of a step counting as the step.
  const double n = std::floor(time / dt + kStepTolerance);
  Substeps s;
  // time - n dt >= -kStepTolerance dt: a rounding error, not time owed.
  s.leftover = std::max(0.0, time - n * dt);
  // Compare as doubles: n can exceed what a long holds after a very long pause.
  s.count = n > static_cast<double>(max_substeps) ? max_substeps : static_cast<long>(n);
  s.dropped = (n - static_cast<double>(s.count)) * dt;
  return s;
  // END ex11.1
}

}  // namespace clothlab
