// slips.hpp: the wrong answers students usually give in the grading cases that name them, each
// worked out from the case's inputs, so that a report says what went wrong in words ("the old
// velocity moved the particle"), not only in numbers. grading::hint picks the one an answer is.
#pragma once

#include <initializer_list>
#include <string>

#include "clothlab/core/types.hpp"

namespace grading {

// A wrong answer and what it means: the value the slip gives for the case's inputs, and the slip
// in words.
struct Slip {
  clothlab::Vec3 value;
  const char* words;
};

// The case's hint: the slip `got` is (to within tol), named first, then the hint that holds
// whatever the answer. A case that names slips chooses inputs where each slip gives a value of
// its own, and none the right one.
inline std::string hint(const clothlab::Vec3& got, std::initializer_list<Slip> slips, double tol,
                        const std::string& general) {
  for (const Slip& s : slips) {
    if (((got - s.value).cwiseAbs().array() <= tol).all())
      return std::string("your answer is what ") + s.words + " gives: " + general;
  }
  return general;
}

namespace slips {

using clothlab::Vec3;
using grading::hint;

// ex01.1, m = 2 kg, g = (0, -9.8, 0): m g = (0, -19.6, 0) N.
inline const std::initializer_list<Slip> kGravity = {
    {Vec3(0.0, -4.9, 0.0), "g divided by the mass (g / m, not m g)"},
    {Vec3(0.0, -9.8, 0.0), "g without the mass (the force is m g)"},
    {Vec3(0.0, 19.6, 0.0), "a flipped sign (gravity pulls along g)"}};
inline constexpr const char* kGravityHint =
    "gravity_force(m, g) must return the force m g; for m = 2 kg and g = (0, -9.8, 0) that is "
    "(0, -19.6, 0) N";

// ex01.3 and ex01.4, one step from v = (4, 5, 6) with f = (2, 0, -4), 1/m = 0.5, dt = 0.1:
// a = (1, 0, -2), v' = v + a dt = (4.1, 5, 5.8). Without dt v + a = (5, 5, 4); without the mass
// v + f dt = (4.2, 5, 5.6); with f / inv_m = f m = (4, 0, -8), (4.4, 5, 5.2); a sign,
// v - a dt = (3.9, 5, 6.2).
inline const std::initializer_list<Slip> kEulerVelocity = {
    {Vec3(5, 5, 4), "the acceleration without dt (v' = v + a dt)"},
    {Vec3(4.2, 5, 5.6), "the force without the mass (a = f / m, that is f * inv_m)"},
    {Vec3(4.4, 5, 5.2), "the force divided by the inverse mass (a = f * inv_m, not f / inv_m)"},
    {Vec3(3.9, 5, 6.2), "a flipped sign (v' = v + a dt)"}};

// ex01.3 from r = (1, 2, 3): r' = r + v dt = (1.4, 2.5, 3.6). With the new velocity
// r + v' dt = (1.41, 2.5, 3.58); without dt r + v = (5, 7, 9).
inline const std::initializer_list<Slip> kExplicitPosition = {
    {Vec3(1.41, 2.5, 3.58),
     "the new velocity v' moving the particle (that is symplectic Euler, exercise 1.4)"},
    {Vec3(5, 7, 9), "the velocity without dt (r' = r + v dt)"}};
inline constexpr const char* kExplicit =
    "explicit Euler: v' = v + (f/m) dt and r' = r + v dt, both from the state at the start";

// ex01.4: r' = r + v' dt = (1.41, 2.5, 3.58). With the old velocity r + v dt = (1.4, 2.5, 3.6);
// without dt r + v' = (5.1, 7, 8.8).
inline const std::initializer_list<Slip> kSymplecticPosition = {
    {Vec3(1.4, 2.5, 3.6),
     "the old velocity v moving the particle (that is explicit Euler, exercise 1.3)"},
    {Vec3(5.1, 7, 8.8), "the velocity without dt (r' = r + v' dt)"}};
inline constexpr const char* kSymplectic =
    "symplectic Euler: v' = v + (f/m) dt first, then r' = r + v' dt with the NEW velocity";

// ex02.1, r2 - r1 = e* = (2, -3, 6), l = 7, ks = 14 N/m, l0 = 5 m, at rest: f_sd = 28 N,
// f1 = 28 e* / 7 = (8, -12, 24) N. A sign gives -f1; e* for e, 28 e* = (56, -84, 168); e* l for
// e, 28 * 7 e* = (392, -588, 1176); no ks, 2 e = (4, -6, 12) / 7.
inline const std::initializer_list<Slip> kStretchedSpring = {
    {Vec3(-8.0, 12.0, -24.0),
     "a flipped sign (f_sd = -ks (l0 - l) pulls a stretched spring together; or e from "
     "particle 2 to 1)"},
    {Vec3(56.0, -84.0, 168.0),
     "e* = r2 - r1 for the direction, not divided by its length l (e = e* / l)"},
    {Vec3(392.0, -588.0, 1176.0), "e* multiplied by the length l instead of divided by it"},
    {Vec3(4.0, -6.0, 12.0) / 7.0, "the stretch without ks"}};
inline constexpr const char* kStretched =
    "a spring stretched 2 m past its rest length with ks = 14 N/m pulls particle 1 toward "
    "particle 2 (along +e = (r2 - r1) / l) with 28 N; a force pointing away from particle 2 "
    "means the sign of f_sd = -ks (l0 - l) is flipped, or e points from 2 to 1";

// ex09.1, r1 = 0, r2 = (6, 0, 8): l = 10, e = (0.6, 0, 0.8), limit 5, so C = 5. With w1 = 3 and
// w2 = 1, dr1 = 3/4 C e = (2.25, 0, 3). The shares swapped give 1/4 C e = (0.75, 0, 1); an even
// split 1/2 C e = (1.5, 0, 2); w1 not divided by w1 + w2, 3 C e = (9, 0, 12).
inline const std::initializer_list<Slip> kStrainShare = {
    {Vec3(0.75, 0.0, 1.0),
     "the shares swapped (particle 1 takes w1 / (w1 + w2): the lighter end moves more)"},
    {Vec3(1.5, 0.0, 2.0), "the correction split evenly, not by inverse mass"},
    {Vec3(9.0, 0.0, 12.0), "w1 not divided by w1 + w2"}};
// ex09.1 with particle 1 pinned, w1 = 0 and w2 = 2: dr1 = 0. The shares swapped give C e =
// (3, 0, 4); an even split (1.5, 0, 2).
inline const std::initializer_list<Slip> kStrainPinned = {
    {Vec3(3.0, 0.0, 4.0),
     "the shares swapped: the pinned particle moved the whole way (its share is w1 / (w1 + w2) = "
     "0)"},
    {Vec3(1.5, 0.0, 2.0),
     "the correction split evenly: the pinned particle moved half way (its share is w1 / (w1 + "
     "w2) = 0)"}};

}  // namespace slips
}  // namespace grading
