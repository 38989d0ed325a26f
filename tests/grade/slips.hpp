// slips.hpp: the wrong answers students usually give in the grading cases that name them, each
// worked out from the case's inputs, so that a report says what went wrong in words ("the old
// velocity moved the particle"), not only in numbers. grading::hint picks the one an answer is.
#pragma once

#include <cmath>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "clothlab/core/types.hpp"

namespace grading {

// A wrong answer and what it means: the value the slip gives for the case's inputs, and the slip
// in words. Most kernels return a Vec3; a case whose answer is a number, a count or a list of
// positions lists SlipOf<double>, SlipOf<int> or SlipOf<std::vector<std::size_t>> instead, one
// whose answer is a list of index pairs SlipOf<IndexPairs> (given, as the answer is, with each pair
// as (smaller, larger) and the list sorted), and the same hint picks among them.
template <typename T>
struct SlipOf {
  T value;
  const char* words;
};
using Slip = SlipOf<clothlab::Vec3>;
using IndexPairs = std::vector<std::pair<clothlab::Index, clothlab::Index>>;

// Whether an answer is a slip's value: each component within tol, or the same count.
inline bool same_answer(const clothlab::Vec3& a, const clothlab::Vec3& b, double tol) {
  return ((a - b).cwiseAbs().array() <= tol).all();
}
inline bool same_answer(double a, double b, double tol) {
  return std::abs(a - b) <= tol;
}
inline bool same_answer(int a, int b, double /*tol*/) {
  return a == b;
}
inline bool same_answer(const std::vector<std::size_t>& a, const std::vector<std::size_t>& b,
                        double /*tol*/) {
  return a == b;
}
inline bool same_answer(const IndexPairs& a, const IndexPairs& b, double /*tol*/) {
  return a == b;
}

// The case's hint: the slip `got` is (to within tol), named first, then the hint that holds
// whatever the answer. A case that names slips chooses inputs where each slip gives a value of
// its own, and none the right one.
template <typename T>
std::string hint(const T& got, std::initializer_list<SlipOf<T>> slips, double tol,
                 const std::string& general) {
  for (const SlipOf<T>& s : slips) {
    if (same_answer(got, s.value, tol))
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

// ex01.2, body 1 at r1, body 2 at r1 + d with d = (2, -3, 6), r = |d| = 7, G = 2, m1 = 3, m2 = 5:
// G m1 m2 = 30, and F = (30 / r^2) (d / r) = (30 / 343) d. G m1 m2 / r^2 times d itself (d is r
// long, not a unit vector): (30 / 49) d, seven times too strong; the unit vector d / r over r^3:
// (30 / 2401) d; r taken as |d|^2 = 49 (squaredNorm for norm), 30 / 49^3 d = (30 / 117649) d; G
// left out, (15 / 343) d; a flipped sign, -(30 / 343) d.
inline const std::initializer_list<Slip> kGravitationNear = {
    {(30.0 / 49.0) * Vec3(2.0, -3.0, 6.0),
     "G m1 m2 / r^2 times d = r2 - r1, which is r long (a force that falls as 1 / r: divide d by "
     "r^3, or use the unit vector d / r)"},
    {(30.0 / 2401.0) * Vec3(2.0, -3.0, 6.0),
     "G m1 m2 / r^3 times the unit vector d / r (r^3 goes with d itself, r^2 with d / r)"},
    {(30.0 / 117649.0) * Vec3(2.0, -3.0, 6.0),
     "r taken as |d|^2 (squaredNorm() where norm() belongs)"},
    {(15.0 / 343.0) * Vec3(2.0, -3.0, 6.0), "G left out (F = G m1 m2 / r^2)"},
    {-(30.0 / 343.0) * Vec3(2.0, -3.0, 6.0),
     "a flipped sign (the pull on body 1 points toward body 2, along d = r2 - r1)"}};
inline constexpr const char* kInverseSquare =
    "F = G m1 m2 / r^2 along (r2 - r1) / r: check you divide by r^2 (or |d|^3 times d)";

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

// ex03.1, a still right triangle of legs 1 m (n* = (0, 0, 1), a0 = 0.5 m^2) in a wind
// v_air = (0, 0, -10): v = (0, 0, 10), f = -1/2 * 1.2 * 100 * 1 * 0.5 n = (0, 0, -30) N. The wind
// not subtracted leaves v = 0: no force. Added (v = v_air), or the sign of f flipped: +30. The
// area |n*| for |n*| / 2: -60. |v| for |v|^2 (the folded form without its |v|): -3.
inline const std::initializer_list<Slip> kAeroHeadOn = {
    {Vec3(0.0, 0.0, 0.0), "the wind not subtracted (v = (v1 + v2 + v3) / 3 - v_air)"},
    {Vec3(0.0, 0.0, 30.0), "a flipped sign (f = -1/2 rho |v|^2 cd a n), or the wind added"},
    {Vec3(0.0, 0.0, -60.0), "the area taken as |n*| (the triangle's area is a0 = |n*| / 2)"},
    {Vec3(0.0, 0.0, -3.0), "|v| where |v|^2 belongs (the folded form is |v| (v . n*) n*)"}};

// ex03.2, rho = 1.2, cd = 0.5, a = 0.1 m^2, u = (3, 0, 4), |u| = 5: f = -0.03 |u| u =
// (-0.45, 0, -0.6) N. A flipped sign +0.45, +0.6; |u| e for |u|^2 e, -0.03 u / |u| * 5 = -0.15 e =
// (-0.09, 0, -0.12); |u|^2 u (a squared norm for the norm), -0.03 * 25 u = (-2.25, 0, -3); no 1/2,
// (-0.9, 0, -1.2).
inline const std::initializer_list<Slip> kParticleDrag = {
    {Vec3(0.45, 0.0, 0.6), "a flipped sign (drag points against u)"},
    {Vec3(-0.09, 0.0, -0.12), "|u| where |u|^2 belongs"},
    {Vec3(-2.25, 0.0, -3.0), "|u|^2 u, a squared norm for the norm (|u|^2 e = |u| u)"},
    {Vec3(-0.9, 0.0, -1.2), "the 1/2 left out (f = -1/2 rho |u|^2 cd a e)"}};

// ex04.1, the number of bending pairs of a 4 x 5 grid: 4 * 3 + 5 * 2 = 22. Each pair added from
// both ends, 44; the pairs one apart (the structural springs), 4 * 4 + 5 * 3 = 31; both loops one
// short (c + 3 < cols), 4 * 2 + 5 * 1 = 13; rows wrapping into the next (i + 2 < 20 for the row
// pairs), 18 + 10 = 28.
inline const std::initializer_list<SlipOf<int>> kBendingCount4x5 = {
    {44, "each pair added twice, once from each end"},
    {31, "pairs one apart (those are the structural springs)"},
    {13, "loops that stop one short (c + 2 < cols allows the last pair)"},
    {28, "row pairs that wrap into the next row (test c + 2 < cols, not i + 2 < rows cols)"}};

// ex04.1, the bending pairs of a 3 x 4 grid (3 rows of 4), particle (r, c) numbered r * 4 + c:
//    0  1  2  3
//    4  5  6  7
//    8  9 10 11
// Along the rows (c = 0, 1): 0-2 1-3 4-6 5-7 8-10 9-11; down the columns (r = 0): 0-8 1-9 2-10
// 3-11: ten pairs. On a square grid each slip below gives the right answer; here each its own:
//  - a column step of 2 * rows = 6: 0-6 1-7 2-8 3-9 down the columns, the rows as they are;
//  - numbered r * rows + c = 3 r + c: the rows 0-2 1-3, 3-5 4-6, 6-8 7-9, the columns from row 0
//    as they are, 0-8 1-9 2-10 3-11;
//  - rows for cols in both, numbered 3 r + c with a column step of 6: the rows as just above,
//    the columns 0-6 1-7 2-8 3-9;
//  - the bounds swapped (c + 2 < rows, r + 2 < cols): c = 0 alone along the rows, 0-2 4-6 8-10,
//    and r = 0, 1 down the columns, 0-8 1-9 2-10 3-11 and 4-12 5-13 6-14 7-15, outside the grid;
//  - the grid read the other way round, 4 rows of 3 (numbered r * 3 + c): the rows 0-2 3-5 6-8
//    9-11, the columns 0-6 1-7 2-8 3-9 4-10 5-11.
// Each list as an answer is compared: sorted, each pair (smaller, larger).
inline const std::initializer_list<SlipOf<IndexPairs>> kBendingPairs3x4 = {
    {{{0, 2}, {0, 6}, {1, 3}, {1, 7}, {2, 8}, {3, 9}, {4, 6}, {5, 7}, {8, 10}, {9, 11}},
     "a column step of 2 * rows (two down a column is i + 2 * cols: a row holds cols particles)"},
    {{{0, 2}, {0, 8}, {1, 3}, {1, 9}, {2, 10}, {3, 5}, {3, 11}, {4, 6}, {6, 8}, {7, 9}},
     "particle (r, c) numbered r * rows + c (it is r * cols + c: a row holds cols particles)"},
    {{{0, 2}, {0, 6}, {1, 3}, {1, 7}, {2, 8}, {3, 5}, {3, 9}, {4, 6}, {6, 8}, {7, 9}},
     "rows where cols belongs, in the numbering r * rows + c and the column step 2 * rows"},
    {{{0, 2},
      {0, 8},
      {1, 9},
      {2, 10},
      {3, 11},
      {4, 6},
      {4, 12},
      {5, 13},
      {6, 14},
      {7, 15},
      {8, 10}},
     "the bounds swapped (along a row c + 2 < cols, down a column r + 2 < rows)"},
    {{{0, 2}, {0, 6}, {1, 7}, {2, 8}, {3, 5}, {3, 9}, {4, 10}, {5, 11}, {6, 8}, {9, 11}},
     "rows and cols swapped throughout: the grid read as cols rows of rows particles"}};

// ex05.1, falling at (0, -4, 0) onto y = 0 with e = 0.5, no friction: v' = (0, 2, 0). v_n kept
// with its sign, e v_n: (0, -2, 0); e left out, -v_n: (0, 4, 0); no bounce at all: (0, -4, 0).
inline const std::initializer_list<Slip> kBounce = {
    {Vec3(0.0, -2.0, 0.0), "v_n scaled by e but not reversed (v_n' = -e v_n)"},
    {Vec3(0.0, 4.0, 0.0), "e left out: a perfectly elastic bounce (v_n' = -e v_n)"},
    {Vec3(0.0, -4.0, 0.0), "the velocity left as it was (nothing bounced)"}};

// ex05.1, v = (3, -2, 4), e = 0.5, mu_s = 0.2, mu_d = 0.1: j = 3 m/s, |v_t| = 5, v' = (2.82, 1,
// 3.76). v_t (1 - mu_d j) = 0.7 v_t: (2.1, 1, 2.8); v_t (1 - mu_d): (2.7, 1, 3.6); mu_d / j in
// place of mu_d j, 1 - 0.1 / 3 / 5 = 0.99333...: (2.98, 1, 3.97333...); no friction: (3, 1, 4).
inline const std::initializer_list<Slip> kDynamicFriction = {
    {Vec3(2.1, 1.0, 2.8), "v_t scaled by (1 - mu_d j), not by (1 - mu_d j / |v_t|)"},
    {Vec3(2.7, 1.0, 3.6), "v_t scaled by (1 - mu_d): friction must take mu_d j off the slide"},
    {Vec3(2.98, 1.0, 4.0 * (1.0 - 0.1 / 15.0)),
     "mu_d / j in place of mu_d j (dynamic friction grows with the impulse j)"},
    {Vec3(3.0, 1.0, 4.0), "friction left out of a fast slide"}};

// ex06.1, l = 3, l0 = l_built = 2, yield_strain = 0.25 (target 3 / 1.25 = 2.4), flow_rate = 2 1/s,
// dt = 0.05 s: the fraction flow_rate dt = 0.1 gives l0' = 2.04. dt alone: 2 + 0.05 * 0.4 = 2.02;
// flow_rate alone, not capped at 1: 2 + 2 * 0.4 = 2.8; a fraction of 1 (flow_rate / dt = 40, or
// flow_rate alone, capped at 1): the whole way, 2.4.
inline const std::initializer_list<SlipOf<double>> kFlowFraction = {
    {2.02, "dt alone as the fraction (it is flow_rate dt)"},
    {2.8, "flow_rate alone as the fraction (it is flow_rate dt, at most 1)"},
    {2.4,
     "a full flow to the target: the fraction came out 1 (flow_rate / dt, or flow_rate "
     "alone, capped at 1; it is flow_rate dt = 0.1)"}};

// ex06.1, built at 1 m with max_strain 0.2, l0 = 0.9, squeezed to 0.3 with a full flow: the target
// 0.3 / 0.9 = 0.333... is clamped to l_built (1 - 0.2) = 0.8. Around l0: 0.9 * 0.8 = 0.72; no
// clamp: 1/3.
inline const std::initializer_list<SlipOf<double>> kClampBelow = {
    {0.72,
     "the clamp taken around l0 (it is [l_built (1 - max_strain), l_built (1 + max_strain)])"},
    {1.0 / 3.0, "the clamp forgotten (the rest length must stay within max_strain of l_built)"}};

// ex06.2, strains {1.2, 3.0, 0.1, 2.5, 1.8, 2.9, 1.3} over tear_strain = 1 with max_tears = 3:
// the three most strained, positions 1 (3.0), 5 (2.9) and 3 (2.5), ascending [1, 3, 5]. The first
// three over the limit: [0, 1, 3]; the three least strained (the ranking turned around), 0 (1.2),
// 6 (1.3) and 4 (1.8): [0, 4, 6]; the most strained in the order of their ranking: [1, 5, 3].
inline const std::initializer_list<SlipOf<std::vector<std::size_t>>> kTearCap = {
    {{0, 1, 3}, "the first max_tears springs over the limit, not the most strained"},
    {{0, 4, 6}, "the least strained kept (rank the most strained first)"},
    {{1, 5, 3}, "the positions left in the order of the ranking (return them ascending)"}};

// ex07.1, a = -4 x, dt = 0.1 s, x = 1 m, v = 0.5 m/s: (x', v') = (1.03, 0.09), written (x', v', 0).
// Plain Euler (1 + 0.05, 0.5 - 0.4) = (1.05, 0.1); a2 at the full Euler step (x2 = 1.05, v2 = 0.1,
// a2 = -4.2): (1 + 0.01, 0.5 - 0.42) = (1.01, 0.08); x moved with v, (1.05, 0.09); with v',
// (1.009, 0.09); with a2 for v2, (1 - 0.41, 0.09) = (0.59, 0.09).
inline const std::initializer_list<Slip> kMidpointSpring = {
    {Vec3(1.05, 0.1, 0.0), "a plain Euler step (a2 and v2 are taken at the half step)"},
    {Vec3(1.01, 0.08, 0.0), "a2 taken at the full Euler step instead of the half step"},
    {Vec3(1.05, 0.09, 0.0), "x moved with the start velocity v instead of v2 (x' = x + dt v2)"},
    {Vec3(1.009, 0.09, 0.0), "x moved with the end velocity v' instead of v2 (x' = x + dt v2)"},
    {Vec3(0.59, 0.09, 0.0), "the acceleration a2 where the velocity v2 belongs (x' = x + dt v2)"}};

// ex07.2, the same spring: (x', v') = (1.0297333..., 0.0927), written (x', v', 0). The stage
// velocities sum to 0.5 + 0.3 + 0.295 + 0.094 = 1.189 and the accelerations to -16.278, so equal
// weights 1/4 give (1 + 0.1 * 1.189 / 4, 0.5 - 0.1 * 16.278 / 4) = (1.029725, 0.09305). The
// midpoint step gives (1.03, 0.09). a2 used twice in v' (as[1] for as[2]):
// v' = 0.5 + 0.1/6 (-4 - 8.2 - 8.2 - 4.118) = 0.5 - 2.4518 / 6 = 0.0913666..., x' unchanged.
inline const std::initializer_list<Slip> kRk4Spring = {
    {Vec3(1.029725, 0.09305, 0.0), "equal weights 1/4 for the stages (they are 1, 2, 2, 1 over 6)"},
    {Vec3(1.03, 0.09, 0.0), "the midpoint step (RK4 takes four stages)"},
    {Vec3(7723.0 / 7500.0, 0.5 - 2.4518 / 6.0, 0.0),
     "a stage's acceleration used twice in v' (as[1] where as[2] belongs): v' averages a1, a2, a3 "
     "and a4"}};

// ex08.1, k = 400 N/m, m = 0.25 kg, c = 1 N s/m (underdamped): c / k = 0.0025 s. c / m = 4;
// k / c = 400; 2 c / k = 0.005; 2 / w with w = sqrt(k / m) = 40, 0.05 (the overdamped formula's
// limit, or the undamped oscillator's); c / (k m) = 0.01.
inline const std::initializer_list<SlipOf<double>> kUnderdampedLimit = {
    {4.0, "c / m (the stiffness k belongs under c: dt = c / k)"},
    {400.0, "k / c, the quotient upside down (dt = c / k)"},
    {0.005, "2 c / k, twice the limit (|R|^2 = 1 - dt c/m + dt^2 k/m <= 1 gives dt <= c / k)"},
    {0.05, "2 / w, a limit without the damper (below critical damping it is c / k)"},
    {0.01, "c / (k m): the mass cancels out of the underdamped limit"}};

// ex10.1, x = (-0.1, 0.1, 0) with h = 0.25: x / h = (-0.4, 0.4, 0), floor (-1, 0, 0), the cell
// written as a Vec3. Truncated toward zero (a cast, std::trunc) or rounded: (0, 0, 0); std::ceil:
// (0, 1, 0).
inline const std::initializer_list<Slip> kNegativeCell = {
    {Vec3(0.0, 0.0, 0.0),
     "-0.4 truncated toward zero (a cast or std::trunc or std::round) in place of std::floor"},
    {Vec3(0.0, 1.0, 0.0), "std::ceil in place of std::floor"}};

// ex10.2, e = 0.5, w1 = 3, w2 = 1, u = (3, -2, 0) along n = (0, 1, 0): j = 3 m/s, friction takes
// mu_d j = 0.6 m/s of the 3 m/s slide, du = (-0.6, 3, 0), v1' = -3/4 du = (0.45, -2.25, 0).
// mu_d / j for mu_d j takes 0.2 / 3 / 3 of u_t: du = (-0.0666..., 3, 0), v1' = (0.05, -2.25, 0);
// the shares swapped, v1' = -1/4 du = (0.15, -0.75, 0); no friction, du = (0, 3, 0),
// v1' = (0, -2.25, 0).
inline const std::initializer_list<Slip> kPairFriction = {
    {Vec3(0.05, -2.25, 0.0), "mu_d / j in place of mu_d j (dynamic friction grows with j)"},
    {Vec3(0.15, -0.75, 0.0),
     "the shares swapped (particle 1 takes w1 / (w1 + w2) of the change: the lighter one more)"},
    {Vec3(0.0, -2.25, 0.0), "friction left out of a sliding pair"}};

// ex11.1, leftover 0.7 ms and a frame of 1.6 ms at dt = 1 ms: 2 steps, 0.3 ms left, nothing
// dropped, written (count, leftover, dropped). Steps counted in the frame time alone but the
// leftover kept from both: (1, 1.3 ms, 0); the old leftover forgotten altogether: (1, 0.6 ms, 0);
// rounded up (std::ceil), (3, 0, 0).
inline const std::initializer_list<Slip> kLeftoverCounts = {
    {Vec3(1.0, 0.0013, 0.0),
     "steps counted in the frame time alone (count them in leftover + frame_time)"},
    {Vec3(1.0, 0.0006, 0.0), "the last frame's leftover forgotten (time = leftover + frame_time)"},
    {Vec3(3.0, 0.0, 0.0), "the steps rounded up (a step is taken only once its time is there)"}};

// ex12.1, iteration 2 of w_i = w_j = 1, alpha_tilde = 1, lambda = -1/3, C = 1/3: delta_lambda =
// (-1/3 + 1/3) / 3 = 0. Without -alpha_tilde lambda, -1/3 / 3 = -1/9; lambda + delta_lambda
// returned, -1/3.
inline const std::initializer_list<SlipOf<double>> kXpbdSecondIteration = {
    {-1.0 / 9.0, "plain PBD, the term -alpha_tilde lambda left out of delta_lambda (hint 2)"},
    {-1.0 / 3.0, "lambda + delta_lambda returned (return delta_lambda alone, hint 4)"}};

// ex13.1, x_i - x_j = (0, -3, -4), l = 5, l0 = 2: d = (0, -1.2, -1.6). x_i - x_j itself:
// (0, -3, -4); x_j - x_i: (0, 1.2, 1.6) for the flip; l0 (x_i - x_j) not divided by l:
// (0, -6, -8); the unit vector without l0: (0, -0.6, -0.8).
inline const std::initializer_list<Slip> kLocalDiagonal = {
    {Vec3(0.0, -3.0, -4.0), "x_i - x_j itself, not rescaled to the rest length l0"},
    {Vec3(0.0, 1.2, 1.6), "a flipped direction (d points along x_i - x_j)"},
    {Vec3(0.0, -6.0, -8.0), "l0 (x_i - x_j), not divided by the length l"},
    {Vec3(0.0, -0.6, -0.8), "the unit direction without the rest length l0"}};

// ex14.1, one spring stretched to l = 1.5 (ks = 100 N/m, l0 = 1 m), m/h^2 = 100 N/m: f = (-50,
// 0, 0), H = diag(200, 133.3, 133.3), dx = (-0.25, 0, 0). Without m/h^2 in H, H = diag(100, 33.3,
// 33.3) and dx = (-0.5, 0, 0): the spring snaps back to l0. f or H with its sign turned: (0.25, 0,
// 0).
inline const std::initializer_list<Slip> kVbdStretched = {
    {Vec3(-0.5, 0.0, 0.0),
     "H without the inertia m/h^2 I (the spring snaps to its rest length as if the vertex weighed "
     "nothing)"},
    {Vec3(0.25, 0.0, 0.0), "f or H with its sign turned (the step pushes the vertex away)"}};
// ex14.1, the squeezed spring: dx = (1/3, 0.1, 0). The factor 1 - l0/l = -1 not clamped makes
// H = diag(150, -50, -50) and the sideways step 5 / -50 = -0.1.
inline const std::initializer_list<Slip> kVbdSqueezed = {
    {Vec3(1.0 / 3.0, -0.1, 0.0),
     "the unclamped Hessian (max(0, 1 - l0/l) across a squeezed spring, not 1 - l0/l)"}};
// ex14.1, the damper at its rest length: H = diag(220, 100, 100), dx = (-1/110, 0, 0). The
// springs' ks S subtracted: H = diag(100 - 100 + 20, 100, 100), dx = -2 / 20 = (-0.1, 0, 0).
inline const std::initializer_list<Slip> kVbdDamper = {
    {Vec3(-0.1, 0.0, 0.0), "the springs' stiffness subtracted from H (H += ks S, not -=)"}};

}  // namespace slips
}  // namespace grading
