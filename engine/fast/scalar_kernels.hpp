// scalar_kernels.hpp: the lecture's kernels for the float room (float_room.hpp), written once on
// the scalar type.
//
// The exercise kernels (spring_damper_force, symplectic_euler_step, ...) take and return
// doubles: they are what the lessons teach and what the fast path calls, bit for bit the
// readable path. A step in single precision needs the same formulas on floats, so they are
// written here again, as templates on Scalar, each beside the equation it computes. The loops of
// the fast path (springs.cpp) are templates on the scalar too: spring_kernel picks, for each
// scalar, what they call: the exercise's kernel on doubles (so the double path keeps its bits
// and its code), this file's spring_force on floats.
#pragma once

#include <cmath>

#include "clothlab/core/types.hpp"
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
  if (l == Scalar(0)) return Vec3Of<Scalar>::Zero();
  const Vec3Of<Scalar> e = e_star * (Scalar(1) / l);                  // one division
  const Scalar f_sd = -ks * (l0 - l) - kd * (e.dot(v1) - e.dot(v2));  // [N]
  return f_sd * e;
}

// The spring kernel the fast path's loops call on Scalar: the exercise's on doubles, the one
// above on floats. The constants stay doubles in the spring set (plasticity changes l0 in place
// every step), and are rounded to the scalar as they are read.
inline Vec3 spring_kernel(const Vec3& r1, const Vec3& r2, const Vec3& v1, const Vec3& v2, double ks,
                          double kd, double l0) {
  return spring_damper_force(r1, r2, v1, v2, ks, kd, l0);
}
inline Vec3f spring_kernel(const Vec3f& r1, const Vec3f& r2, const Vec3f& v1, const Vec3f& v2,
                           double ks, double kd, double l0) {
  return spring_force<float>(r1, r2, v1, v2, static_cast<float>(ks), static_cast<float>(kd),
                             static_cast<float>(l0));
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
