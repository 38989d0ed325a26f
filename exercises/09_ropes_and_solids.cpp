// Lesson 09, ropes and soft solids: the exercise kernel.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`, and
// watch a cloth held taut by your code with
//   ./build/clothlab-student run lessons/09-ropes-and-solids/taut-cloth.toml
// Every symbol is explained in lessons/09-ropes-and-solids/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include <cmath>

#include "clothlab/after_step/strain_limiting.hpp"
#include "clothlab/core/not_implemented.hpp"

namespace clothlab {

// Exercise ex09.1: one strain-limiting correction (Provot's deformation constraint) for one spring
// (see strain_limiting.hpp).
//   e* = r2 - r1,  l = |e*|,  e = e* / l
//   target = (1 + max_strain) l0 if l is longer, (1 - max_compression) l0 if l is shorter;
//   within [(1 - max_compression) l0, (1 + max_strain) l0] nothing moves.
//   C = l - target,  dr1 = +w1 / (w1 + w2) C e,  dr2 = -w2 / (w1 + w2) C e
// Hints:
//   1. Return the zero correction (StrainCorrection{}) first for what cannot or need not move:
//      both ends pinned (w1 + w2 = 0), coincident ends (l = 0, no direction to move along),
//      and a spring within its limits.
//   2. Correct to the limit, not to l0: the spring may keep any length within the limits.
//   3. The lighter end moves more: the share of particle 1 is w1 / (w1 + w2). A pinned end,
//      w = 0, gets a share of exactly 0.
//   4. Check the signs on a stretched spring: particle 1 moves toward particle 2 (along +e),
//      particle 2 toward particle 1; and the new length comes out as the target.
StrainCorrection strain_limit_correction(const Vec3& r1, const Vec3& r2, double w1, double w2,
                                         double l0, const StrainLimits& limits) {
  // BEGIN ex09.1: see lessons/09-ropes-and-solids/README.md
  CLOTHLAB_TODO("ex09.1", "lessons/09-ropes-and-solids/README.md");
  // END ex09.1
}

}  // namespace clothlab
