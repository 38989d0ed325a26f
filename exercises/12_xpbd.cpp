// Lesson 12, position-based dynamics and XPBD: the exercise kernel.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`, and
// watch a cloth held by your constraints with
//   ./build/clothlab-student run lessons/12-xpbd/stiff-curtain.toml
// Every symbol is explained in lessons/12-xpbd/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include <cmath>

#include "clothlab/core/not_implemented.hpp"
#include "clothlab/integrators/xpbd.hpp"

namespace clothlab {

// Exercise ex12.1: one XPBD projection of a distance constraint (see xpbd.hpp).
//   d = x_i - x_j,  l = |d|,  n = d / l           grad_i C = n, grad_j C = -n
//   C = l - l0
//   delta_lambda = (-C - alpha_tilde lambda) / (w_i + w_j + alpha_tilde)
//   x_i += w_i delta_lambda n,   x_j -= w_j delta_lambda n;   return delta_lambda
// Hints:
//   1. Return 0 and move nothing first for what cannot move: w_i + w_j = 0 (both ends pinned;
//      with alpha_tilde = 0 the division would be -C / 0) and l = 0 (no direction n).
//   2. The term -alpha_tilde lambda is what makes XPBD's stiffness independent of the
//      iterations: lambda is what this constraint has already pushed in this step. Leave it out
//      and a second iteration pulls the ends together again.
//   3. Check the signs on a stretched pair (C > 0): delta_lambda < 0, and x_i moves toward x_j.
//   4. Return delta_lambda, not the new lambda: the caller adds it up.
double xpbd_distance_projection(Vec3& x_i, Vec3& x_j, double w_i, double w_j, double l0,
                                double alpha_tilde, double lambda) {
  // BEGIN ex12.1: see lessons/12-xpbd/README.md
  CLOTHLAB_TODO("ex12.1", "lessons/12-xpbd/README.md");
  // END ex12.1
}

}  // namespace clothlab
