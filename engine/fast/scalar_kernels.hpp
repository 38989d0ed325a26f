// scalar_kernels.hpp: the lecture's kernels for the float room (float_room.hpp), written once on
// the scalar type.
//
// The exercise kernels (spring_damper_force, symplectic_euler_step, ...) take and return
// doubles: they are what the lessons teach and what the fast path calls, bit for bit the
// readable path. A step in single precision needs the same formulas on floats, so they are
// written here again, as templates on Scalar, each beside the equation it computes. The loops of
// the fast path (springs.cpp, aerodynamics.cpp) are templates on the scalar too: on doubles they
// call the exercise's kernel (so the double path keeps its bits and its code), on floats this
// file's (spring_kernel picks for the springs' loops; aerodynamics.cpp chooses in its loop).
#pragma once

#include <cmath>

#include "clothlab/core/types.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab::fast {

template <class Scalar>
using Vec3Of = Eigen::Matrix<Scalar, 3, 1>;
using Vec3f = Vec3Of<float>;

// Lesson 02's spring-damper, f1 on particle 1 [N] (f2 = -f1): e* = r2 - r1, l = |e*|, e = e*/l,
// f_sd = -ks (l0 - l) - kd (e.v1 - e.v2), f1 = f_sd e; no force between coincident ends, which
// give no direction (as the reference kernel, solutions/02_spring_dampers.cpp).
template <class Scalar>
Vec3Of<Scalar> spring_force(const Vec3Of<Scalar>& r1, const Vec3Of<Scalar>& r2,
                            const Vec3Of<Scalar>& v1, const Vec3Of<Scalar>& v2, Scalar ks,
                            Scalar kd, Scalar l0) {
  const Vec3Of<Scalar> e_star = r2 - r1;  // [m]
  const Scalar l = e_star.norm();
  const Vec3Of<Scalar> e = e_star * (Scalar(1) / l);                  // one division
  const Scalar f_sd = -ks * (l0 - l) - kd * (e.dot(v1) - e.dot(v2));  // [N]
  // Coincident ends (l = 0, e not a number) give no force. Chosen at the end, not by returning
  // early: then a loop over springs reads every spring's inputs whatever its l, and Clang takes
  // several springs an instruction (in the page's WebAssembly, the early return kept it to one).
  return l == Scalar(0) ? Vec3Of<Scalar>::Zero().eval() : (f_sd * e).eval();
}

// The spring kernel the fast path's loops call on Scalar: the exercise's on doubles, the one
// above on floats. The constants stay doubles in the spring set (plasticity changes l0 in place
// every step); the float room rounds them to float once, when they change (springs.cpp).
inline Vec3 spring_kernel(const Vec3& r1, const Vec3& r2, const Vec3& v1, const Vec3& v2, double ks,
                          double kd, double l0) {
  return spring_damper_force(r1, r2, v1, v2, ks, kd, l0);
}
inline Vec3f spring_kernel(const Vec3f& r1, const Vec3f& r2, const Vec3f& v1, const Vec3f& v2,
                           float ks, float kd, float l0) {
  return spring_force<float>(r1, r2, v1, v2, ks, kd, l0);
}

// Lesson 03's air on a triangle, the whole force [N] (each corner takes a third):
//   v = (v1 + v2 + v3) / 3 - v_air (each corner's relative velocity first),
//   n* = (r2 - r1) x (r3 - r1),  f = -1/2 rho cd (|v| (v . n*) / (2 |n*|)) n*,
// zero for a triangle of no area or no relative velocity (as the reference kernel,
// solutions/03_aerodynamics.cpp).
template <class Scalar>
Vec3Of<Scalar> aerodynamic_force_of(const Vec3Of<Scalar>& r1, const Vec3Of<Scalar>& r2,
                                    const Vec3Of<Scalar>& r3, const Vec3Of<Scalar>& v1,
                                    const Vec3Of<Scalar>& v2, const Vec3Of<Scalar>& v3,
                                    const Vec3Of<Scalar>& v_air, Scalar rho, Scalar cd) {
  const Vec3Of<Scalar> v = ((v1 - v_air) + (v2 - v_air) + (v3 - v_air)) / Scalar(3);  // [m/s]
  const Vec3Of<Scalar> n_star = (r2 - r1).cross(r3 - r1);  // |n*| = twice the area [m^2]
  const Scalar n_star_norm = n_star.norm();
  const Scalar speed = v.norm();
  if (n_star_norm == Scalar(0) || speed == Scalar(0)) return Vec3Of<Scalar>::Zero();
  const Vec3Of<Scalar> v2_a_n = (speed * v.dot(n_star) / (Scalar(2) * n_star_norm)) * n_star;
  return Scalar(-0.5) * rho * cd * v2_a_n;
}

// Lesson 01's Euler steps of one particle, a = f / m (inv_m = 0 for a pinned one):
//   explicit Euler    r' = r + v dt,  v' = v + a dt
//   symplectic Euler  v' = v + a dt,  r' = r + v' dt   (the lecture's, with the new velocity)
template <class Scalar>
struct PointStateOf {
  Vec3Of<Scalar> r, v;
};

template <class Scalar>
PointStateOf<Scalar> explicit_euler(const Vec3Of<Scalar>& r, const Vec3Of<Scalar>& v,
                                    const Vec3Of<Scalar>& f, Scalar inv_m, Scalar dt) {
  const Vec3Of<Scalar> a = f * inv_m;
  return {r + v * dt, v + a * dt};
}

template <class Scalar>
PointStateOf<Scalar> symplectic_euler(const Vec3Of<Scalar>& r, const Vec3Of<Scalar>& v,
                                      const Vec3Of<Scalar>& f, Scalar inv_m, Scalar dt) {
  const Vec3Of<Scalar> a = f * inv_m;
  const Vec3Of<Scalar> v_next = v + a * dt;
  return {r + v_next * dt, v_next};
}

}  // namespace clothlab::fast
