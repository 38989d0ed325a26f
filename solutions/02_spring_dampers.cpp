// Lesson 02, spring-dampers: the exercise kernels.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`.
// Watch a cloth hang on your springs with
//   ./build/clothlab-student run lessons/02-spring-dampers/hanging-cloth.toml
// Every symbol is explained in lessons/02-spring-dampers/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

// Exercise ex02.1: the spring-damper force on particle 1.
//   e* = r2 - r1,  l = |e*|,  e = e* / l
//   v1 = e . v1,   v2 = e . v2
//   f_sd = -ks (l0 - l) - kd (v1 - v2),   f1 = f_sd e
// Hints:
//   1. Compute e* and l first. If l == 0 the particles coincide and e is undefined: return
//      Vec3::Zero() (a NaN here would spread to the whole cloth in a few steps).
//   2. A stretched spring (l > l0) must pull particle 1 toward particle 2, i.e. along +e.
//   3. The damper only sees the velocities along e: project v1 and v2 with a dot product.
Vec3 spring_damper_force(const Vec3& r1, const Vec3& r2, const Vec3& v1, const Vec3& v2, double ks,
                         double kd, double l0) {
  // BEGIN ex02.1: see lessons/02-spring-dampers/README.md
  const Vec3 e_star = r2 - r1;  // from particle 1 to particle 2 [m]
  const double l = e_star.norm();
  if (l == 0.0) return Vec3::Zero();    // coincident particles: no direction to act along
  const Vec3 e = e_star * (1.0 / l);    // unit vector from 1 to 2: e* / l, with one division
  const double v1_along_e = e.dot(v1);  // [m/s]
  const double v2_along_e = e.dot(v2);  // [m/s]
  const double f_sd = -ks * (l0 - l) - kd * (v1_along_e - v2_along_e);  // spring + damper [N]
  return f_sd * e;                                                      // f1 = f_sd e [N]
  // END ex02.1
}

// Exercise ex02.2: the energy stored in the spring, U = 1/2 ks (l - l0)^2.
// Hints:
//   1. l = |r2 - r1|. The damper stores no energy: kd does not appear.
//   2. The spring force is minus the slope of this energy: the grader checks the two agree.
double spring_energy(const Vec3& r1, const Vec3& r2, double ks, double l0) {
  // BEGIN ex02.2: see lessons/02-spring-dampers/README.md
  const double stretch = (r2 - r1).norm() - l0;  // [m], negative when compressed
  return 0.5 * ks * stretch * stretch;
  // END ex02.2
}

}  // namespace clothlab
