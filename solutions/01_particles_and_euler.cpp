// Lesson 01, particles and Euler: the exercise kernels.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`, and
// watch a scene run on your code with
//   ./build/clothlab-student run lessons/01-particles-and-euler/projectile.toml
// Every symbol is explained in lessons/01-particles-and-euler/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/forces/gravitation.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/euler.hpp"

namespace clothlab {

// Exercise ex01.1: uniform gravity, f = m g.
// Hints:
//   1. m is a mass [kg] and g an acceleration [m/s^2]: their product is a force [N].
//   2. One line. Eigen lets you multiply a scalar by a Vec3 directly.
Vec3 gravity_force(double m, const Vec3& g) {
  // BEGIN ex01.1: see lessons/01-particles-and-euler/README.md
  return m * g;
  // END ex01.1
}

// Exercise ex01.2: Newton's gravitation, F = G m1 m2 / r^2, on body 1 toward body 2.
// Hints:
//   1. d = r2 - r1 points from body 1 to body 2; r = |d| is their distance.
//   2. The force on body 1 points along d / r (toward body 2) with magnitude G m1 m2 / r^2.
//   3. Fold the two: G m1 m2 / r^3 * d needs one norm and no normalize().
//   4. If r == 0 there is no direction: return Vec3::Zero() instead of dividing by zero.
Vec3 gravitation_force(const Vec3& r1, double m1, const Vec3& r2, double m2, double G) {
  // BEGIN ex01.2: see lessons/01-particles-and-euler/README.md
  const Vec3 d = r2 - r1;  // from body 1 toward body 2 [m]
  const double r = d.norm();
  if (r == 0.0) return Vec3::Zero();  // coincident bodies: no direction to pull along
  return (G * m1 * m2 / (r * r * r)) * d;
  // END ex01.2
}

// Exercise ex01.3: explicit (forward) Euler. Everything on the right uses the OLD state:
//   a = f / m,   v' = v + a dt,   r' = r + v dt.
// Hints:
//   1. You are given inv_m = 1/m, so a = f * inv_m (a pinned particle has inv_m = 0).
//   2. Move the position with the velocity you were given, not the one you just computed.
PointState explicit_euler_step(const Vec3& r, const Vec3& v, const Vec3& f, double inv_m,
                               double dt) {
  // BEGIN ex01.3: see lessons/01-particles-and-euler/README.md
  const Vec3 a = f * inv_m;  // Newton: a = f / m
  return {r + v * dt, v + a * dt};
  // END ex01.3
}

// Exercise ex01.4: the lecture's Euler, semi-implicit (symplectic):
//   a = f / m,   v' = v + a dt,   r' = r + v' dt.
// Hints:
//   1. Same as 1.3 except for one symbol: the position moves with the NEW velocity v'.
//   2. Compute v' first, then r'.
PointState symplectic_euler_step(const Vec3& r, const Vec3& v, const Vec3& f, double inv_m,
                                 double dt) {
  // BEGIN ex01.4: see lessons/01-particles-and-euler/README.md
  const Vec3 a = f * inv_m;          // Newton: a = f / m
  const Vec3 v_next = v + a * dt;    // velocity first ...
  return {r + v_next * dt, v_next};  // ... then the position moves with it
  // END ex01.4
}

}  // namespace clothlab
