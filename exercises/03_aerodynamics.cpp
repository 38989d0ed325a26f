// Lesson 03, aerodynamics: the exercise kernels.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`.
// Watch a flag in the wind on your code with
//   ./build/clothlab-student run lessons/03-aerodynamics/flag.toml
// Every symbol is explained in lessons/03-aerodynamics/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/forces/aerodynamics.hpp"

namespace clothlab {

// Exercise ex03.1: the aerodynamic force on one triangle.
//   v = (v1 + v2 + v3) / 3 - v_air,   n* = (r2 - r1) x (r3 - r1)
//   f_aero = -1/2 rho cd (|v| (v . n*) / (2 |n*|)) n*
// Hints:
//   1. v is the triangle's velocity relative to the air: subtract the wind.
//   2. Use the folded form above: no normalize(), one norm of v and one of n*.
//   3. A degenerate triangle has |n*| == 0: return zero rather than divide by it. (Written
//      unfolded, with n = n* / |n*| and a = a0 (v . n) / |v|, you must also guard |v| == 0.)
//   4. Check the sign: a triangle moving into still air along its normal is pushed back.
Vec3 aerodynamic_force(const Vec3& r1, const Vec3& r2, const Vec3& r3, const Vec3& v1,
                       const Vec3& v2, const Vec3& v3, const Vec3& v_air, double rho, double cd) {
  // BEGIN ex03.1: see lessons/03-aerodynamics/README.md
  CLOTHLAB_TODO("ex03.1", "lessons/03-aerodynamics/README.md");
  // END ex03.1
}

// Exercise ex03.2: fluid drag on one particle, f = -1/2 rho |u|^2 cd a e with u = v - v_air.
// Hints:
//   1. e = u / |u| points along the relative velocity; the force points the other way.
//   2. |u|^2 e = |u| u: no division needed, and u = 0 gives zero by itself.
Vec3 fluid_drag_force(const Vec3& v, const Vec3& v_air, double rho, double cd, double a) {
  // BEGIN ex03.2: see lessons/03-aerodynamics/README.md
  CLOTHLAB_TODO("ex03.2", "lessons/03-aerodynamics/README.md");
  // END ex03.2
}

}  // namespace clothlab
