// Lesson 13, a local/global solver (fast mass-springs): the exercise kernel.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`, and
// watch a cloth stepped by your local step with
//   ./build/clothlab-student run lessons/13-local-global/canvas-curtain.toml
// Every symbol is explained in lessons/13-local-global/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include <cmath>

#include "clothlab/core/not_implemented.hpp"
#include "clothlab/integrators/local_global.hpp"

namespace clothlab {

// Exercise ex13.1: the local step for one spring (see local_global.hpp).
//   e = x_i - x_j,  l = |e|
//   d = l0 e / l                     the vector of length l0 nearest to e
// Hints:
//   1. Coincident ends (l = 0) give no direction: return d_previous as it is, never NaN.
//   2. d points from x_j to x_i, the same way as x_i - x_j: the global step then pulls a
//      stretched spring's ends together.
//   3. |d| = l0 whatever l is: the local step does not look at ks, kd or the masses.
Vec3 local_step_projection(const Vec3& x_i, const Vec3& x_j, double l0, const Vec3& d_previous) {
  // BEGIN ex13.1: see lessons/13-local-global/README.md
  const Vec3 e = x_i - x_j;
  const double l = e.norm();        // [m]
  if (l == 0.0) return d_previous;  // coincident ends: no direction, keep the last one
  return l0 * (e / l);              // e / l first: l0 / l could overflow for a tiny l
  // END ex13.1
}

}  // namespace clothlab
