// Grading tests for lesson 03, aerodynamics (exercises ex03.1 and ex03.2).
//
// Every expected value is worked out in the comment beside it, from the lesson's equations;
// none comes from the reference solution. Each case calls its exercise's kernel and checks it
// against a hand-worked triangle or particle, a limit case (air along the surface, a flat
// triangle, no relative wind) or an invariant (force along the normal, only the relative
// velocity counts, winding does not matter, the force scales with rho, cd and |v|^2).
#include <array>
#include <sstream>
#include <string>

#include "clothlab/forces/aerodynamics.hpp"
#include "grading.hpp"

using clothlab::Vec3;

namespace {

// A triangle, its corner velocities and the air around it.
struct AeroCase {
  Vec3 r1, r2, r3;  // corners [m]
  Vec3 v1, v2, v3;  // corner velocities [m/s]
  Vec3 v_air;       // wind [m/s]
  double rho;       // air density [kg/m^3]
  double cd;        // drag coefficient
};

// Fixed, "random-looking" triangles: tilted, of different sizes, corners moving differently,
// and wind that is neither along the normal nor in the plane.
const std::array<AeroCase, 3> kTriangles = {{
    {Vec3(0.0, 0.0, 0.0), Vec3(0.3, 0.1, -0.2), Vec3(-0.1, 0.4, 0.25), Vec3(1.0, -0.5, 2.0),
     Vec3(0.8, -0.2, 2.5), Vec3(1.3, -0.9, 1.6), Vec3(-3.0, 1.0, 0.5), 1.225, 1.0},
    {Vec3(2.0, 1.0, -1.0), Vec3(3.5, 0.2, -0.4), Vec3(2.4, 2.2, 0.3), Vec3(0.0, 0.0, 0.0),
     Vec3(0.1, 0.0, 0.0), Vec3(0.0, -0.1, 0.0), Vec3(4.0, 6.0, -2.0), 1.2, 0.8},
    {Vec3(-0.5, 0.7, 0.1), Vec3(-0.45, 0.75, 0.02), Vec3(-0.52, 0.79, 0.12), Vec3(-6.0, 2.0, 1.0),
     Vec3(-5.5, 2.5, 0.0), Vec3(-6.5, 1.5, 2.0), Vec3(0.0, 0.0, 0.0), 1000.0, 1.3},
}};

// "corners (..) (..) (..), corner velocities (..) (..) (..), wind (..), rho = .., cd = ..":
// names the input of a failed check.
std::string describe(const AeroCase& t) {
  std::ostringstream out;
  out << "triangle with corners " << grading::show(t.r1) << " " << grading::show(t.r2) << " "
      << grading::show(t.r3) << ", corner velocities " << grading::show(t.v1) << " "
      << grading::show(t.v2) << " " << grading::show(t.v3) << ", wind " << grading::show(t.v_air)
      << ", rho = " << t.rho << ", cd = " << t.cd;
  return out.str();
}

Vec3 force_on(const AeroCase& t) {
  return clothlab::aerodynamic_force(t.r1, t.r2, t.r3, t.v1, t.v2, t.v3, t.v_air, t.rho, t.cd);
}

}  // namespace

TEST_SUITE("ex03") {
  // --- Exercise ex03.1: the aerodynamic force on a triangle -------------------------------------

  TEST_CASE("ex03.1 air hitting a right triangle head on pushes with 30 N" * POINTS(1)) {
    // Right triangle with legs of 1 m in the x-y plane: r1 = 0, r2 = (1, 0, 0), r3 = (0, 1, 0).
    // n* = (1, 0, 0) x (0, 1, 0) = (0, 0, 1), |n*| = 1, n = (0, 0, 1), a0 = |n*| / 2 = 0.5 m^2.
    // The triangle is still and the wind blows at v_air = (0, 0, -10) m/s, straight onto it:
    // v = 0 - v_air = (0, 0, 10), |v| = 10, v . n = 10, a = a0 (v . n) / |v| = 0.5 m^2.
    // f = -1/2 rho |v|^2 cd a n = -1/2 * 1.2 * 100 * 1 * 0.5 * (0, 0, 1) = (0, 0, -30) N:
    // the wind pushes the triangle the way it blows.
    const Vec3 f = clothlab::aerodynamic_force(Vec3::Zero(), Vec3(1.0, 0.0, 0.0),
                                               Vec3(0.0, 1.0, 0.0), Vec3::Zero(), Vec3::Zero(),
                                               Vec3::Zero(), Vec3(0.0, 0.0, -10.0), 1.2, 1.0);
    // The usual slips (the wind not subtracted, or added; a sign; the area |n*|; |v| for |v|^2)
    // and what each gives here are worked out in slips.hpp (kAeroHeadOn): the report names the
    // one an answer is, then the hint that holds whatever the answer.
    INFO(grading::hint(f, grading::slips::kAeroHeadOn, 1e-9,
                       "a still triangle of area 0.5 m^2 facing a 10 m/s wind (rho = 1.2, cd = "
                       "1) feels 1/2 rho |v|^2 cd a = 30 N, along the wind (-z)"));
    CHECK_NEAR_VEC(f, Vec3(0.0, 0.0, -30.0), 1e-9);
  }

  TEST_CASE("ex03.1 air at an angle sees only the cross-sectional area" * POINTS(1)) {
    // Right triangle with legs 2 m (along x) and 1 m (along y): n* = (2, 0, 0) x (0, 1, 0) =
    // (0, 0, 2), |n*| = 2, n = (0, 0, 1), a0 = 1 m^2. Still triangle, wind v_air = (-8, 0, -6):
    // v = (8, 0, 6), |v| = 10, v . n = 6, so the air meets the surface at cos(angle) = 0.6 and
    // sees a = a0 * 0.6 = 0.6 m^2. With rho = 1.2 and cd = 1.5:
    // f = -1/2 * 1.2 * 100 * 1.5 * 0.6 * n = -54 n = (0, 0, -54) N. The force is along the
    // normal, not along the wind: the sideways part of the wind slides along the surface.
    {
      const Vec3 f = clothlab::aerodynamic_force(Vec3::Zero(), Vec3(2.0, 0.0, 0.0),
                                                 Vec3(0.0, 1.0, 0.0), Vec3::Zero(), Vec3::Zero(),
                                                 Vec3::Zero(), Vec3(-8.0, 0.0, -6.0), 1.2, 1.5);
      INFO(
          "the air sees the area a = a0 (v . n) / |v| = 0.6 m^2, not the full 1 m^2, and the "
          "force is along the normal n: expected (0, 0, -54) N. -90 N means the full area a0 was "
          "used; -108 N means n* was not normalised; x components mean the force was put along "
          "v instead of n");
      CHECK_NEAR_VEC(f, Vec3(0.0, 0.0, -54.0), 1e-9);
    }
    // The same triangle turned by a rotation R and moved by t. A rotation keeps lengths, angles
    // and cross products (R a x R b = R (a x b)), so every quantity turns with it and the force
    // becomes R (0, 0, -54) N. Now the air moves too (wind w) and the corners move differently:
    // v_i = R (8, 0, 6) + w + R d_i with d1 + d2 + d3 = 0, so the mean corner velocity minus
    // the wind is still R (8, 0, 6).
    {
      const Eigen::Matrix3d R =
          Eigen::AngleAxisd(0.7, Vec3(1.0, 2.0, 2.0) / 3.0).toRotationMatrix();
      const Vec3 t(0.4, -2.0, 1.5);
      const Vec3 w(1.5, -0.5, 2.0);
      const Vec3 rel = R * Vec3(8.0, 0.0, 6.0);
      const Vec3 d1(1.0, 2.0, -3.0), d2(-2.0, 0.5, 1.0), d3(1.0, -2.5, 2.0);  // sum to zero
      const Vec3 f = clothlab::aerodynamic_force(t, R * Vec3(2.0, 0.0, 0.0) + t,
                                                 R * Vec3(0.0, 1.0, 0.0) + t, rel + w + R * d1,
                                                 rel + w + R * d2, rel + w + R * d3, w, 1.2, 1.5);
      INFO(
          "the same triangle and relative wind, turned and moved, must feel the turned force "
          "R (0, 0, -54) N. Use the mean of the three corner velocities, (v1 + v2 + v3) / 3, "
          "minus the wind, and the normal from the corners as given (no axis is special)");
      CHECK_NEAR_VEC(f, R * Vec3(0.0, 0.0, -54.0), 1e-9);
    }
  }

  TEST_CASE("ex03.1 the force is along the normal and against the relative velocity" * POINTS(1)) {
    // f = -1/2 rho |v|^2 cd a n with a = a0 (v . n) / |v|: f is a multiple of n (so f x n = 0),
    // and f . v = -1/2 rho cd a0 |v| (v . n)^2 < 0 whenever v . n != 0: the air always resists
    // the triangle's motion through it, never helps it.
    for (const AeroCase& tri : kTriangles) {
      INFO(describe(tri));
      const Vec3 f = force_on(tri);
      const Vec3 n = (tri.r2 - tri.r1).cross(tri.r3 - tri.r1).normalized();
      const Vec3 v = (tri.v1 + tri.v2 + tri.v3) / 3.0 - tri.v_air;
      {
        INFO(
            "the aerodynamic force must be along the triangle's normal n = n* / |n*|: the part "
            "of the wind along the surface does not push (do not put the force along v)");
        CHECK_NEAR_VEC(f.cross(n), Vec3::Zero(), 1e-9 * (1.0 + f.norm()));
      }
      {
        INFO(
            "the force must oppose the relative velocity v = mean corner velocity - v_air: "
            "f . n must have the opposite sign of v . n. Check the minus sign in "
            "f = -1/2 rho |v|^2 cd a n, that the wind is subtracted (not added), and that "
            "a = a0 (v . n) / |v| keeps the sign of v . n (no absolute value)");
        CHECK(f.norm() > 0.0);
        CHECK(f.dot(n) * v.dot(n) < 0.0);
        CHECK(f.dot(v) < 0.0);
      }
    }
  }

  TEST_CASE("ex03.1 only the relative velocity matters and the winding does not" * POINTS(1)) {
    // A general triangle (the first of the fixed ones) with u = (2, -1, 3) m/s of relative
    // velocity.
    const Vec3 r1 = kTriangles[0].r1, r2 = kTriangles[0].r2, r3 = kTriangles[0].r3;
    const Vec3 u(2.0, -1.0, 3.0);
    const Vec3 moving = clothlab::aerodynamic_force(r1, r2, r3, u, u, u, Vec3::Zero(), 1.2, 1.0);
    {
      // A triangle moving at u through still air and a still triangle in a wind of -u are the
      // same thing seen from two frames: v = u - 0 = 0 - (-u). So is a triangle moving at u + w
      // in a wind w.
      const Vec3 in_wind = clothlab::aerodynamic_force(r1, r2, r3, Vec3::Zero(), Vec3::Zero(),
                                                       Vec3::Zero(), -u, 1.2, 1.0);
      const Vec3 w(5.0, 0.5, -4.0);
      const Vec3 both_moving =
          clothlab::aerodynamic_force(r1, r2, r3, u + w, u + w, u + w, w, 1.2, 1.0);
      INFO(
          "only the velocity relative to the air counts: v = (v1 + v2 + v3) / 3 - v_air. A "
          "still triangle in a wind of -u must feel what a triangle moving at u in still air "
          "feels");
      CHECK(moving.norm() > 0.0);
      CHECK_NEAR_VEC(in_wind, moving, 1e-9 * (1.0 + moving.norm()));
      CHECK_NEAR_VEC(both_moving, moving, 1e-9 * (1.0 + moving.norm()));
    }
    {
      // Listing the corners the other way round (r1, r3, r2) flips n* to -n*, but the force
      // holds n twice, through a = a0 (v . n) / |v| and through n itself: (v . (-n)) (-n) =
      // (v . n) n, so the force is the same.
      const Vec3 flipped = clothlab::aerodynamic_force(r1, r3, r2, u, u, u, Vec3::Zero(), 1.2, 1.0);
      INFO(
          "the force must not depend on the order of the corners: keep the sign of v . n in the "
          "area a = a0 (v . n) / |v| (do not take its absolute value, do not use a0 alone)");
      CHECK_NEAR_VEC(flipped, moving, 1e-9 * (1.0 + moving.norm()));
    }
  }

  TEST_CASE("ex03.1 air along the surface or a flat triangle gives zero and no NaN" * POINTS(1)) {
    // The right triangle of legs 1 m in the x-y plane, n = (0, 0, 1).
    const Vec3 r1 = Vec3::Zero(), r2(1.0, 0.0, 0.0), r3(0.0, 1.0, 0.0);
    {
      // Edge-on wind, in the triangle's plane: v . n = 0, so a = 0 and f = 0.
      const Vec3 f = clothlab::aerodynamic_force(r1, r2, r3, Vec3::Zero(), Vec3::Zero(),
                                                 Vec3::Zero(), Vec3(5.0, -3.0, 0.0), 1.2, 1.0);
      INFO(
          "air blowing along the surface sees no area (a = a0 (v . n) / |v| = 0) and must not "
          "push: a force here means the full area a0 was used, or the force was put along v");
      CHECK_NEAR_VEC(f, Vec3::Zero(), 1e-12);
      // Tilt that wind out of the plane, v_air = (4, 0, -3): v = (-4, 0, 3), |v| = 5,
      // v . n = 3, a = 0.5 * 3 / 5 = 0.3 m^2, f = -1/2 * 1.2 * 25 * 1 * 0.3 n = (0, 0, -4.5) N.
      const Vec3 tilted = clothlab::aerodynamic_force(r1, r2, r3, Vec3::Zero(), Vec3::Zero(),
                                                      Vec3::Zero(), Vec3(4.0, 0.0, -3.0), 1.2, 1.0);
      INFO(
          "a wind of (4, 0, -3) m/s meets the same triangle at v . n / |v| = 0.6 and pushes with "
          "1/2 rho |v|^2 cd a = 4.5 N along -n");
      CHECK_NEAR_VEC(tilted, Vec3(0.0, 0.0, -4.5), 1e-9);
    }
    {
      // No relative wind: the corners move with the air, v = 0, and a = a0 (v . n) / |v| is
      // 0 / 0. There is no force.
      const Vec3 w(1.0, 2.0, 3.0);
      const Vec3 f = clothlab::aerodynamic_force(r1, r2, r3, w, w, w, w, 1.2, 1.0);
      INFO(
          "a triangle moving with the air feels nothing: when |v| == 0 return Vec3::Zero() "
          "instead of dividing by |v|");
      CHECK(f.allFinite());
      CHECK_NEAR_VEC(f, Vec3::Zero(), 1e-12);
    }
    {
      // A flat (degenerate) triangle: corners on one line, r3 - r1 = 2 (r2 - r1), so
      // n* = (r2 - r1) x 2 (r2 - r1) = 0 exactly. No area, no normal, no force.
      const Vec3 f = clothlab::aerodynamic_force(Vec3(1.0, 1.0, 1.0), Vec3(2.0, 3.0, 4.0),
                                                 Vec3(3.0, 5.0, 7.0), Vec3::Zero(), Vec3::Zero(),
                                                 Vec3::Zero(), Vec3(0.0, 0.0, -10.0), 1.2, 1.0);
      INFO(
          "a triangle whose corners lie on a line has no area and no normal: when |n*| == 0 "
          "return Vec3::Zero() instead of dividing by |n*|");
      CHECK(f.allFinite());
      CHECK_NEAR_VEC(f, Vec3::Zero(), 1e-12);
    }
  }

  TEST_CASE("ex03.1 the force grows with rho and cd and with the square of the speed" * POINTS(1)) {
    // f = -1/2 rho |v|^2 cd a0 ((v . n) / |v|) n. Doubling every velocity (corners and wind)
    // doubles v: |v|^2 gives 4, the angle is unchanged, so f is 4 times larger. f is linear in
    // rho and in cd. Doubling the triangle's size (corners scaled by 2 about r1) multiplies
    // its area a0 by 4 and leaves n unchanged: f is 4 times larger too.
    const AeroCase& tri = kTriangles[1];
    const Vec3 f0 = force_on(tri);
    const double tol = 1e-9 * (1.0 + f0.norm());
    CHECK(f0.norm() > 0.0);
    {
      AeroCase faster = tri;
      faster.v1 *= 2.0;
      faster.v2 *= 2.0;
      faster.v3 *= 2.0;
      faster.v_air *= 2.0;
      INFO("twice the relative speed must give 4 times the force: f grows with |v|^2");
      CHECK_NEAR_VEC(force_on(faster), 4.0 * f0, 4.0 * tol);
    }
    {
      AeroCase denser = tri;
      denser.rho *= 3.0;
      INFO("three times the air density must give three times the force");
      CHECK_NEAR_VEC(force_on(denser), 3.0 * f0, 3.0 * tol);
    }
    {
      AeroCase smoother = tri;
      smoother.cd *= 0.5;
      INFO("half the drag coefficient must give half the force");
      CHECK_NEAR_VEC(force_on(smoother), 0.5 * f0, tol);
    }
    {
      AeroCase bigger = tri;
      bigger.r2 = tri.r1 + 2.0 * (tri.r2 - tri.r1);
      bigger.r3 = tri.r1 + 2.0 * (tri.r3 - tri.r1);
      INFO(
          "a triangle twice as large has 4 times the area and must feel 4 times the force: "
          "16 times means the unnormalised n* was used as the normal, as well as its area");
      CHECK_NEAR_VEC(force_on(bigger), 4.0 * f0, 4.0 * tol);
    }
  }

  // --- Exercise ex03.2: fluid drag on a particle ------------------------------------------------

  TEST_CASE("ex03.2 drag on a particle worked by hand" * POINTS(2)) {
    // rho = 1.2 kg/m^3, cd = 0.5, a = 0.1 m^2.
    {
      // In still air at v = (3, 0, 4): u = v, |u| = 5, e = (0.6, 0, 0.8).
      // |f| = 1/2 * 1.2 * 25 * 0.5 * 0.1 = 0.75 N, f = -0.75 e = (-0.45, 0, -0.6) N.
      const Vec3 f = clothlab::fluid_drag_force(Vec3(3.0, 0.0, 4.0), Vec3::Zero(), 1.2, 0.5, 0.1);
      // What the usual slips give here is worked out in slips.hpp (kParticleDrag).
      INFO(grading::hint(f, grading::slips::kParticleDrag, 1e-12,
                         "a particle at 5 m/s in still air feels 1/2 rho |u|^2 cd a = 0.75 N "
                         "against its motion"));
      CHECK_NEAR_VEC(f, Vec3(-0.45, 0.0, -0.6), 1e-12);
    }
    {
      // Moving at v = (1, 2, 3) in a wind v_air = (-2, 2, -1): u = v - v_air = (3, 0, 4), the
      // same relative velocity as above, so the same force (-0.45, 0, -0.6) N.
      const Vec3 f =
          clothlab::fluid_drag_force(Vec3(1.0, 2.0, 3.0), Vec3(-2.0, 2.0, -1.0), 1.2, 0.5, 0.1);
      INFO("drag depends on the velocity relative to the fluid: u = v - v_air");
      CHECK_NEAR_VEC(f, Vec3(-0.45, 0.0, -0.6), 1e-12);
    }
    {
      // At rest in a wind of (10, 0, 0): u = (-10, 0, 0), |f| = 1/2 * 1.2 * 100 * 0.5 * 0.1
      // = 3 N, f = -3 (-1, 0, 0) = (3, 0, 0) N: the wind carries the particle along.
      const Vec3 f = clothlab::fluid_drag_force(Vec3::Zero(), Vec3(10.0, 0.0, 0.0), 1.2, 0.5, 0.1);
      INFO(
          "a still particle in a 10 m/s wind is pushed along the wind with 3 N: a zero force "
          "means the wind was not subtracted");
      CHECK_NEAR_VEC(f, Vec3(3.0, 0.0, 0.0), 1e-12);
    }
  }

  TEST_CASE("ex03.2 drag opposes the relative velocity and grows with its square" * POINTS(2)) {
    // f = -1/2 rho |u|^2 cd a u / |u|: parallel to u (f x u = 0), pointing against it
    // (f . u < 0), of magnitude 1/2 rho |u|^2 cd a; twice u gives 4 times f.
    // The last velocity is close to the wind's: a slow relative motion, u ~ (1, 2, -0.5) mm/s.
    const Vec3 v_air(0.5, 1.0, -0.25);
    const std::array<Vec3, 3> velocities = {Vec3(0.3, -2.0, 1.1), Vec3(-12.0, 4.0, 7.5),
                                            Vec3(0.501, 1.002, -0.2505)};
    const double rho = 1.225, cd = 0.47, a = 0.02;
    for (const Vec3& v : velocities) {
      const Vec3 u = v - v_air;
      const Vec3 f = clothlab::fluid_drag_force(v, v_air, rho, cd, a);
      const double magnitude = 0.5 * rho * u.squaredNorm() * cd * a;
      INFO("relative velocity u = " << grading::show(u));
      {
        INFO("drag must point straight against u = v - v_air");
        CHECK_NEAR_VEC(f.cross(u), Vec3::Zero(), 1e-9 * (1e-12 + f.norm() * u.norm()));
        CHECK(f.dot(u) < 0.0);
      }
      {
        INFO("the magnitude of drag is 1/2 rho |u|^2 cd a");
        CHECK(f.norm() == doctest::Approx(magnitude).epsilon(1e-9).scale(0.0));
      }
      {
        const Vec3 f2 = clothlab::fluid_drag_force(2.0 * v, 2.0 * v_air, rho, cd, a);
        INFO("twice the relative speed must give 4 times the drag: f grows with |u|^2");
        CHECK_NEAR_VEC(f2, 4.0 * f, 1e-9 * (1e-12 + 4.0 * f.norm()));
      }
    }
  }

  TEST_CASE("ex03.2 no relative motion means no drag and no NaN" * POINTS(1)) {
    // v == v_air: u = 0, |u|^2 e = |u| u = 0. Computing e = u / |u| first would give 0 / 0.
    const Vec3 w(1.5, -2.0, 0.5);
    const Vec3 f = clothlab::fluid_drag_force(w, w, 1.2, 0.5, 0.1);
    INFO(
        "a particle moving with the fluid feels no drag: write |u|^2 e as |u| u, or return "
        "Vec3::Zero() when |u| == 0, instead of dividing by |u|");
    CHECK(f.allFinite());
    CHECK_NEAR_VEC(f, Vec3::Zero(), 0.0);
    // A slow relative motion is not zero: u = (0, 0.3, -0.4), |u| = 0.5 m/s,
    // f = -1/2 * 1.2 * 0.5 * 0.1 * |u| u = -0.015 u = (0, -0.0045, 0.006) N.
    const Vec3 slow = clothlab::fluid_drag_force(w + Vec3(0.0, 0.3, -0.4), w, 1.2, 0.5, 0.1);
    INFO("0.5 m/s through the fluid gives 1/2 rho |u|^2 cd a = 7.5 mN against u");
    CHECK_NEAR_VEC(slow, Vec3(0.0, -0.0045, 0.006), 1e-12);
  }

}  // TEST_SUITE("ex03")
