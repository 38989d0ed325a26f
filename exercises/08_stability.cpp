// Lesson 08, stability: the exercise kernel.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`, and
// ask the time-step advisor, which calls your kernel for explicit Euler, with
//   ./build/clothlab-student validate lessons/08-stability/damped-spring.toml
// Every symbol is explained in lessons/08-stability/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include <cmath>
#include <limits>

#include "clothlab/core/not_implemented.hpp"
#include "clothlab/integrators/stability_limit.hpp"

namespace clothlab {

// Exercise ex08.1: the largest stable dt of explicit Euler on m x'' = -k x - c x' (see
// stability_limit.hpp). One step multiplies each solution e^(lambda t) by R = 1 + dt lambda,
// where lambda^2 + (c/m) lambda + k/m = 0; the step is stable while |R| <= 1 for both roots.
// Hints:
//   1. Underdamped, c^2 < 4 k m: the roots are complex, |R|^2 = 1 - dt c/m + dt^2 k/m, and
//      |R| <= 1 up to dt = c / k. With c = 0 that is 0: unstable at every dt.
//   2. Otherwise both roots are real and negative; the faster one, lambda_f, reaches R = -1 at
//      dt = -2 / lambda_f = 4 m / (c + sqrt(c^2 - 4 k m)).
//   3. No spring (k = 0): lambda = -c/m (and 0, the position, which never grows), so
//      dt <= 2 m / c; with no damper either, every dt is stable:
//      std::numeric_limits<double>::infinity().
double largest_stable_dt_explicit_euler(double k, double m, double c) {
  // BEGIN ex08.1: see lessons/08-stability/README.md
  CLOTHLAB_TODO("ex08.1", "lessons/08-stability/README.md");
  // END ex08.1
}

}  // namespace clothlab
