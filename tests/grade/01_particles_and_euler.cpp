// Grading tests for lesson 01, particles and Euler (exercises ex01.1 to ex01.4).
//
// Every expected value is worked out in the comment beside it, from the lesson's equations;
// none comes from the reference solution.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "clothlab/forces/gravitation.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/euler.hpp"
#include "grading.hpp"

using clothlab::PointState;
using clothlab::Vec3;
using namespace grading::slips;

namespace {

// explicit_euler_step and symplectic_euler_step share this signature.
using EulerStep = PointState (*)(const Vec3& r, const Vec3& v, const Vec3& f, double inv_m,
                                 double dt);

// A 2 kg particle dropped from rest at the origin under g = (0, -9.8, 0) m/s^2, after 100 steps
// of 0.01 s (t = 1 s): where it is and how fast it falls.
PointState fall_for_one_second(EulerStep step) {
  Vec3 r = Vec3::Zero(), v = Vec3::Zero();
  const Vec3 f(0.0, -9.8 * 2.0, 0.0);  // m = 2 kg
  for (int k = 0; k < 100; ++k) {
    const auto s = step(r, v, f, 0.5, 0.01);
    r = s.r;
    v = s.v;
  }
  return {r, v};
}

}  // namespace

TEST_SUITE("ex01") {
  // --- Exercise ex01.1: uniform gravity --------------------------------------------------------

  TEST_CASE("ex01.1 gravity on a 2 kg particle is m g" * POINTS(1)) {
    // f = m g = 2 kg * (0, -9.8, 0) m/s^2 = (0, -19.6, 0) N.
    const Vec3 f = clothlab::gravity_force(2.0, Vec3(0.0, -9.8, 0.0));
    // What the usual slips give (g / m, g alone, -m g) is worked out in slips.hpp.
    INFO(hint(f, kGravity, 1e-9, kGravityHint));
    CHECK_NEAR_VEC(f, Vec3(0.0, -19.6, 0.0), 1e-12);
  }

  TEST_CASE("ex01.1 gravity follows g in any direction and scales with the mass" * POINTS(1)) {
    // A tilted g: every component is scaled by m. m = 0.3 kg, g = (1.5, -2, 0.25) m/s^2
    // gives (0.45, -0.6, 0.075) N. With no gravity (g = 0) there is no force.
    const Vec3 g(1.5, -2.0, 0.25);
    const Vec3 tilted = clothlab::gravity_force(0.3, g);
    const Vec3 none = clothlab::gravity_force(0.3, Vec3::Zero());
    INFO("f = m g holds component by component, whatever the direction of g");
    CHECK_NEAR_VEC(tilted, Vec3(0.45, -0.6, 0.075), 1e-12);
    CHECK_NEAR_VEC(none, Vec3::Zero(), 0.0);
  }

  // --- Exercise ex01.2: Newton's gravitation ---------------------------------------------------

  TEST_CASE("ex01.2 two 1 kg bodies 1 m apart with G = 1 pull with 1 N" * POINTS(1)) {
    // F = G m1 m2 / r^2 = 1 * 1 * 1 / 1^2 = 1 N, on body 1 toward body 2 (+x).
    const Vec3 f = clothlab::gravitation_force(Vec3::Zero(), 1.0, Vec3(1.0, 0.0, 0.0), 1.0, 1.0);
    INFO("the force on body 1 points from body 1 toward body 2, with magnitude G m1 m2 / r^2");
    CHECK_NEAR_VEC(f, Vec3(1.0, 0.0, 0.0), 1e-12);
  }

  TEST_CASE("ex01.2 one kilogram on the Earth's surface weighs about 9.82 N" * POINTS(1)) {
    // Earth: M = 5.972e24 kg, radius R = 6.371e6 m, G = 6.673e-11 N m^2/kg^2.
    // F = G M m / R^2 = 6.673e-11 * 5.972e24 * 1 / (6.371e6)^2 = 9.8180 N, toward the Earth's
    // centre: for a body at (0, R, 0) above a centre at the origin that is the -y direction.
    const Vec3 f = clothlab::gravitation_force(Vec3(0.0, 6.371e6, 0.0), 1.0, Vec3::Zero(), 5.972e24,
                                               6.673e-11);
    INFO("with the real G, Newton's law gives the familiar weight of 1 kg: about 9.82 N, downward");
    CHECK_NEAR_VEC(f, Vec3(0.0, -9.8180, 0.0), 1e-3);
  }

  TEST_CASE("ex01.2 the pull falls with the square of the distance" * POINTS(1)) {
    // Along an arbitrary direction d: doubling the distance divides the force by 4, and the force
    // stays parallel to d. Here d = (2, -3, 6), |d| = 7, G = 2, m1 = 3, m2 = 5: |F| = 2 * 3 * 5 /
    // 49 = 30 / 49 N, along d / 7 (what the usual slips give instead is worked out in slips.hpp).
    const Vec3 r1(1.0, 1.0, 1.0);
    const Vec3 d(2.0, -3.0, 6.0);
    const Vec3 near_force = clothlab::gravitation_force(r1, 3.0, r1 + d, 5.0, 2.0);
    const Vec3 far_force = clothlab::gravitation_force(r1, 3.0, r1 + 2.0 * d, 5.0, 2.0);
    INFO(hint(near_force, kGravitationNear, 1e-9, kInverseSquare));
    CHECK_NEAR_VEC(near_force, (30.0 / 49.0) * d / 7.0, 1e-12);
    CHECK_NEAR_VEC(far_force, near_force / 4.0, 1e-12);
  }

  TEST_CASE("ex01.2 equal and opposite and finite for coincident bodies" * POINTS(1)) {
    // Newton's third law: the force on 2 due to 1 is minus the force on 1 due to 2.
    // b - a = d = (1, -1.5, 3), |d| = 3.5 (half of (2, -3, 6)), G m1 m2 = 0.5 * 2 * 7 = 7:
    // |F| = 7 / 3.5^2 = 4/7 N along d / 3.5, so f12 = (8/49) d = (8, -12, 24) / 49 N.
    {
      const Vec3 a(0.3, -1.2, 2.0), b(1.3, -2.7, 5.0);
      const Vec3 f12 = clothlab::gravitation_force(a, 2.0, b, 7.0, 0.5);
      const Vec3 f21 = clothlab::gravitation_force(b, 7.0, a, 2.0, 0.5);
      INFO("gravitation_force(r1, m1, r2, m2) must equal -gravitation_force(r2, m2, r1, m1)");
      CHECK_NEAR_VEC(f12 + f21, Vec3::Zero(), 1e-12);
      INFO(
          "bodies of 2 and 7 kg 3.5 m apart with G = 0.5 pull with 7 / 3.5^2 = 4/7 N, along "
          "r2 - r1");
      CHECK_NEAR_VEC(f12, Vec3(8.0, -12.0, 24.0) / 49.0, 1e-12);
    }
    // Two bodies at the same point: there is no direction to pull along, and 1 / 0 would make a
    // NaN that spreads through the whole simulation. The lesson asks for a zero force.
    {
      const Vec3 a(0.3, -1.2, 2.0);
      const Vec3 same = clothlab::gravitation_force(a, 2.0, a, 7.0, 0.5);
      INFO("for r1 == r2 return Vec3::Zero() instead of dividing by zero");
      CHECK(same.allFinite());
      CHECK_NEAR_VEC(same, Vec3::Zero(), 0.0);
    }
  }

  // --- Exercise ex01.3: explicit Euler ---------------------------------------------------------

  TEST_CASE("ex01.3 one explicit Euler step worked by hand" * POINTS(1)) {
    // r = (1, 2, 3), v = (4, 5, 6), f = (2, 0, -4), 1/m = 0.5, dt = 0.1:
    // a = f / m = (1, 0, -2); v' = v + a dt = (4.1, 5, 5.8);
    // r' = r + v dt = (1.4, 2.5, 3.6)   (the OLD velocity moves the particle).
    const auto s =
        clothlab::explicit_euler_step(Vec3(1, 2, 3), Vec3(4, 5, 6), Vec3(2, 0, -4), 0.5, 0.1);
    INFO(hint(s.v, kEulerVelocity, 1e-9, hint(s.r, kExplicitPosition, 1e-9, kExplicit)));
    CHECK_NEAR_VEC(s.v, Vec3(4.1, 5.0, 5.8), 1e-12);
    CHECK_NEAR_VEC(s.r, Vec3(1.4, 2.5, 3.6), 1e-12);
  }

  TEST_CASE("ex01.3 a particle at rest does not move in its first explicit step" * POINTS(1)) {
    // v = 0: explicit Euler moves r by v dt = 0, even though a force acts; only v changes, by
    // (f / m) dt = (0, -9.8, 0) * 2.5 * 0.01 = (0, -0.245, 0) for m = 0.4 kg (1/m = 2.5).
    const auto s =
        clothlab::explicit_euler_step(Vec3(0, 5, 0), Vec3::Zero(), Vec3(0, -9.8, 0), 2.5, 0.01);
    INFO(
        "if r changed here you moved the particle with the NEW velocity: that is exercise 1.4's "
        "symplectic Euler, not explicit Euler");
    CHECK_NEAR_VEC(s.r, Vec3(0, 5, 0), 0.0);
    CHECK_NEAR_VEC(s.v, Vec3(0, -0.245, 0), 1e-12);
  }

  TEST_CASE("ex01.3 a pinned particle (inverse mass 0) is not accelerated" * POINTS(1)) {
    // 1/m = 0: a = f * 0 = 0 whatever the force, so v stays and r moves by v dt.
    const auto s =
        clothlab::explicit_euler_step(Vec3(1, 1, 1), Vec3(0, 0, 2), Vec3(1e6, -1e6, 3), 0.0, 0.5);
    INFO("use a = f * inv_m: an immovable particle has inv_m = 0, never divide by a mass");
    CHECK_NEAR_VEC(s.v, Vec3(0, 0, 2), 0.0);
    CHECK_NEAR_VEC(s.r, Vec3(1, 1, 2), 1e-12);
  }

  TEST_CASE("ex01.3 free fall lags the exact parabola by g dt t / 2" * POINTS(1)) {
    // From rest under g, after n steps explicit Euler has v_k = -g k dt and
    // y_n = sum_{k<n} v_k dt = -g dt^2 n(n-1)/2. With dt = 0.01, n = 100 (t = 1 s), g = 9.8:
    // y = -9.8e-4 * 4950 = -4.851 m, while the exact -g t^2 / 2 = -4.9 m.
    const auto [r, v] = fall_for_one_second(clothlab::explicit_euler_step);
    INFO("after 100 steps of 0.01 s from rest, explicit Euler gives y = -4.851 m and v = -9.8 m/s");
    CHECK(r.y() == doctest::Approx(-4.851).epsilon(1e-9));
    CHECK(v.y() == doctest::Approx(-9.8).epsilon(1e-9));
  }

  // --- Exercise ex01.4: symplectic Euler -------------------------------------------------------

  TEST_CASE("ex01.4 one symplectic Euler step worked by hand" * POINTS(1)) {
    // Same inputs as ex01.3: a = (1, 0, -2), v' = (4.1, 5, 5.8), and now
    // r' = r + v' dt = (1 + 0.41, 2 + 0.5, 3 + 0.58) = (1.41, 2.5, 3.58).
    const auto s =
        clothlab::symplectic_euler_step(Vec3(1, 2, 3), Vec3(4, 5, 6), Vec3(2, 0, -4), 0.5, 0.1);
    INFO(hint(s.v, kEulerVelocity, 1e-9, hint(s.r, kSymplecticPosition, 1e-9, kSymplectic)));
    CHECK_NEAR_VEC(s.v, Vec3(4.1, 5.0, 5.8), 1e-12);
    CHECK_NEAR_VEC(s.r, Vec3(1.41, 2.5, 3.58), 1e-12);
  }

  TEST_CASE("ex01.4 free fall leads the exact parabola by g dt t / 2" * POINTS(1)) {
    // Using the new velocity: y_n = sum_{k=1..n} v_k dt = -g dt^2 n(n+1)/2.
    // dt = 0.01, n = 100: y = -9.8e-4 * 5050 = -4.949 m (exact -4.9 m), v = -9.8 m/s.
    const auto [r, v] = fall_for_one_second(clothlab::symplectic_euler_step);
    INFO(
        "after 100 steps of 0.01 s from rest, symplectic Euler gives y = -4.949 m; -4.851 m "
        "would mean the old velocity moved the particle (explicit Euler)");
    CHECK(r.y() == doctest::Approx(-4.949).epsilon(1e-9));
    CHECK(v.y() == doctest::Approx(-9.8).epsilon(1e-9));
  }

  TEST_CASE("ex01.4 a spring's energy stays bounded over 100 periods" * POINTS(2)) {
    // A 0.5 kg mass (1/m = 2) on a spring k = 2 pi^2 N/m (w = sqrt(k / m) = 2 pi: period 1 s),
    // started at x = 1 m, at rest; the force -k x is fed back every step. dt = 0.01 s, so
    // h w = 2 pi * 0.01 = 0.063. Symplectic Euler keeps a nearby "modified" energy exactly, so
    // E = (m v^2 + k x^2) / 2 only wobbles, by about h w = 6 % at most, for ever. Explicit Euler
    // multiplies E by 1 + (h w)^2 every step: after 10^4 steps E grows by e^(0.0395 * 10^4), far
    // beyond 10 %. Half a period in (50 steps) the mass is at the far side, x = -1 m to within
    // the wobble (0.1 m here); a mass that never moves is not, nor one whose acceleration is
    // f / inv_m (then w = pi, and half a second is a quarter period: x near 0).
    const double k = 2.0 * std::numbers::pi * std::numbers::pi, m = 0.5;
    Vec3 r(1, 0, 0), v = Vec3::Zero();
    const double e0 = 0.5 * k;
    double worst = 0.0;
    bool finite = true;
    Vec3 half_period = Vec3::Zero();
    for (int step = 0; step < 10000; ++step) {
      const auto s = clothlab::symplectic_euler_step(r, v, -k * r, 1.0 / m, 0.01);
      r = s.r;
      v = s.v;
      const double e = 0.5 * m * v.squaredNorm() + 0.5 * k * r.squaredNorm();
      finite = finite && std::isfinite(e);
      worst = std::max(worst, std::abs(e / e0 - 1.0));
      if (step == 49) half_period = r;
    }
    INFO(
        "the energy of an undamped spring must stay within 10 % of its start over 10^4 steps; "
        "growing energy is the mark of explicit Euler (position moved with the old velocity)");
    CHECK(finite);
    CHECK(worst < 0.10);
    INFO(
        "after half a period (50 steps of 0.01 s, period 1 s) the mass must be at the far side "
        "of the spring, near x = -1 m; it is at "
        << grading::show(half_period) << ": check a = f * inv_m");
    CHECK_NEAR_VEC(half_period, Vec3(-1.0, 0.0, 0.0), 0.1);
  }

}  // TEST_SUITE("ex01")
