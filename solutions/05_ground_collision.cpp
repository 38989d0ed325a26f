// Lesson 05, ground collision: the exercise kernel.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`.
// Drop a cloth on the floor on your code with
//   ./build/clothlab-student run lessons/05-ground-collision/cloth-on-floor.toml
// Every symbol is explained in lessons/05-ground-collision/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/core/not_implemented.hpp"

namespace clothlab {

// Exercise ex05.1: the response of a particle found `depth` inside a solid with outward normal n.
//   r' = r + depth n                                   (back onto the surface)
//   v_n = (v . n) n,  v_t = v - v_n
//   if v . n < 0:  j = (1 + e) |v . n|,  v_n' = -e v_n  (bounce)
//                  |v_t| <= mu_s j:  v_t' = 0           (static friction: it sticks)
//                  otherwise:        v_t' = v_t (1 - mu_d j / |v_t|)   (dynamic: it slides)
//   else (already moving out): the velocity is left as it is.
// Hints:
//   1. n is a unit vector; split v with one dot product.
//   2. Friction acts only during a bounce: no approach, no impulse j, no friction.
//   3. Dynamic friction slows the sliding but never reverses it: 1 - mu_d j / |v_t| > 0 whenever
//      |v_t| > mu_s j and mu_d <= mu_s.
PointState collision_response(const Vec3& r, const Vec3& v, const Vec3& n, double depth, double e,
                              double mu_s, double mu_d) {
  // BEGIN ex05.1: see lessons/05-ground-collision/README.md
  const Vec3 r_out = r + depth * n;  // back onto the surface
  const double vn = v.dot(n);        // [m/s], < 0 when moving into the solid
  if (vn >= 0.0) return {r_out, v};  // already leaving: nothing to bounce
  const Vec3 v_n = vn * n;
  const Vec3 v_t = v - v_n;
  const double j = (1.0 + e) * -vn;  // normal impulse per unit mass [m/s]
  const double slide = v_t.norm();
  Vec3 v_t_out = Vec3::Zero();                                     // static friction: it sticks
  if (slide > mu_s * j) v_t_out = v_t * (1.0 - mu_d * j / slide);  // dynamic: it slides on
  return {r_out, -e * v_n + v_t_out};
  // END ex05.1
}

}  // namespace clothlab
