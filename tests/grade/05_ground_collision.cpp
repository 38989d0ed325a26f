// Grading tests for lesson 05, ground collision (exercise ex05.1).
//
// Every expected value is worked out in the comment beside it, from the lesson's equations;
// none comes from the reference solution. Each case calls collision_response and checks it
// against a hand-worked bounce, a limit case (e = 1, e = 0, no approach) or an invariant
// (friction never adds energy, never speeds up or reverses the slide).
#include <array>
#include <sstream>
#include <string>

#include "clothlab/after_step/ground_collision.hpp"
#include "grading.hpp"

using clothlab::Vec3;

namespace {

// One contact: a particle's velocity, the surface's outward unit normal and the contact
// constants, for the case that checks an invariant on several inputs.
struct Contact {
  Vec3 v;       // velocity [m/s]
  Vec3 n;       // outward normal (normalised before use)
  double e;     // restitution
  double mu_s;  // static friction coefficient
  double mu_d;  // dynamic friction coefficient
};

// Fixed inputs, all moving into the solid (v . n < 0) and all with e < 1: tilted normals,
// slides that stick and slides that keep going, a slide just past the static limit with
// mu_d = mu_s (the most friction dynamic friction can ever take), and a slow slide under a large
// friction coefficient (where a dynamic formula without the static branch would reverse it).
const std::array<Contact, 6> kContacts = {{
    {Vec3(0.8, -1.0, -0.6), Vec3(0.0, 1.0, 0.0), 0.3, 0.5, 0.4},
    {Vec3(1.2, 0.5, -2.5), Vec3(2.0, -3.0, 6.0), 0.7, 0.6, 0.6},
    {Vec3(-3.0, -1.0, 2.0), Vec3(0.6, 0.8, 0.0), 0.0, 1.0, 0.9},
    {Vec3(0.1, 0.2, 3.0), Vec3(0.0, 0.0, -1.0), 0.9, 0.05, 0.05},
    {Vec3(0.7, -0.2, 0.0), Vec3(0.0, 1.0, 0.0), 0.5, 2.0, 2.0},
    {Vec3(0.1, -2.0, 0.1), Vec3(0.0, 1.0, 0.0), 0.5, 0.5, 0.5},
}};

// "v = (..), n = (..), e = .., mu_s = .., mu_d = ..": names the input of a failed check.
std::string describe(const Contact& c) {
  std::ostringstream out;
  out << "contact v = " << grading::show(c.v) << " m/s, n = " << grading::show(c.n.normalized())
      << ", e = " << c.e << ", mu_s = " << c.mu_s << ", mu_d = " << c.mu_d;
  return out.str();
}

}  // namespace

TEST_SUITE("ex05") {
  // --- Exercise ex05.1: the collision response -------------------------------------------------

  TEST_CASE("ex05.1 a particle below the ground comes back up and bounces at half speed" *
            POINTS(1)) {
    // Ground y = 0, outward normal n = (0, 1, 0). The particle ended the step 0.02 m deep, at
    // r = (0.5, -0.02, 1), so r' = r + 0.02 n = (0.5, 0, 1): back on the plane. No friction
    // (mu_s = mu_d = 0), e = 0.5.
    const Vec3 r(0.5, -0.02, 1.0), n(0.0, 1.0, 0.0);
    {
      // Falling straight down at v = (0, -4, 0): v . n = -4 < 0, v_n' = -0.5 (0, -4, 0) =
      // (0, 2, 0).
      const clothlab::PointState s =
          clothlab::collision_response(r, Vec3(0.0, -4.0, 0.0), n, 0.02, 0.5, 0.0, 0.0);
      {
        INFO(
            "the particle must be moved out by depth along the normal, r' = r + depth n: 0.02 m "
            "deep below y = 0 puts it back at y = 0");
        CHECK_NEAR_VEC(s.r, Vec3(0.5, 0.0, 1.0), 1e-12);
      }
      {
        // What the usual slips give here is worked out in slips.hpp (kBounce).
        INFO(grading::hint(s.v, grading::slips::kBounce, 1e-12,
                           "a particle hitting the ground at 4 m/s with e = 0.5 leaves at 2 m/s "
                           "upward: v_n' = -e v_n"));
        CHECK_NEAR_VEC(s.v, Vec3(0.0, 2.0, 0.0), 1e-12);
      }
    }
    {
      // Falling and sliding, v = (3, -4, -1): v_n = (0, -4, 0), v_t = (3, 0, -1). Without
      // friction only the normal part changes: v' = (0, 2, 0) + (3, 0, -1) = (3, 2, -1).
      const clothlab::PointState s =
          clothlab::collision_response(r, Vec3(3.0, -4.0, -1.0), n, 0.02, 0.5, 0.0, 0.0);
      INFO(
          "only the normal part v_n = (v . n) n bounces; the tangential part v_t = v - v_n keeps "
          "going, and with mu_s = mu_d = 0 nothing slows it");
      CHECK_NEAR_VEC(s.r, Vec3(0.5, 0.0, 1.0), 1e-12);
      CHECK_NEAR_VEC(s.v, Vec3(3.0, 2.0, -1.0), 1e-12);
    }
  }

  TEST_CASE("ex05.1 e = 1 keeps the speed and e = 0 stops the normal motion" * POINTS(1)) {
    // Ground normal n = (0, 1, 0), no friction, v = (1.5, -2, 0.5): v_n = (0, -2, 0),
    // v_t = (1.5, 0, 0.5).
    const Vec3 r(-1.0, -0.1, 0.25), v(1.5, -2.0, 0.5), n(0.0, 1.0, 0.0);
    const clothlab::PointState elastic = clothlab::collision_response(r, v, n, 0.1, 1.0, 0.0, 0.0);
    const clothlab::PointState plastic = clothlab::collision_response(r, v, n, 0.1, 0.0, 0.0, 0.0);
    {
      // e = 1: v_n' = (0, 2, 0), v' = (1.5, 2, 0.5), a mirror image with |v'| = |v|.
      INFO(
          "with e = 1 (elastic) the bounce is a mirror image: the normal part is reversed at full "
          "size and the speed is kept");
      CHECK_NEAR_VEC(elastic.v, Vec3(1.5, 2.0, 0.5), 1e-12);
    }
    {
      // e = 0: v_n' = 0, v' = (1.5, 0, 0.5): it slides along the ground without bouncing.
      INFO(
          "with e = 0 (no bounce) the normal motion stops, v_n' = 0, and the particle slides on "
          "along the surface");
      CHECK_NEAR_VEC(plastic.v, Vec3(1.5, 0.0, 0.5), 1e-12);
    }
  }

  TEST_CASE("ex05.1 static friction holds a slow slide and dynamic friction slows a fast one" *
            POINTS(1)) {
    // Ground normal n = (0, 1, 0), e = 0.5, mu_s = 0.2, mu_d = 0.1. Both particles hit at
    // v . n = -2 m/s: the impulse is j = (1 + e) |v . n| = 1.5 * 2 = 3 m/s and v_n' = (0, 1, 0).
    // Static friction can hold up to mu_s j = 0.6 m/s of sliding.
    const Vec3 r(2.0, -0.01, -3.0), n(0.0, 1.0, 0.0);
    {
      // Slow slide v_t = (0.3, 0, 0.4), |v_t| = 0.5 <= 0.6: it sticks, v_t' = 0,
      // v' = (0, 1, 0).
      const clothlab::PointState s =
          clothlab::collision_response(r, Vec3(0.3, -2.0, 0.4), n, 0.01, 0.5, 0.2, 0.1);
      INFO(
          "a slide of 0.5 m/s is within the static limit mu_s j = 0.2 * 3 = 0.6 m/s, with "
          "j = (1 + e) |v . n| = 3 m/s: the particle sticks and only the bounce is left. Compare "
          "|v_t| with mu_s j, not with mu_s alone or with mu_s |v . n|");
      CHECK_NEAR_VEC(s.v, Vec3(0.0, 1.0, 0.0), 1e-12);
    }
    {
      // Fast slide v_t = (3, 0, 4), |v_t| = 5 > 0.6: dynamic friction takes mu_d j = 0.3 m/s
      // off the slide, along its own direction: v_t' = v_t (1 - 0.3 / 5) = 0.94 (3, 0, 4) =
      // (2.82, 0, 3.76), so v' = (2.82, 1, 3.76) and the slide goes on at 4.7 m/s.
      const clothlab::PointState s =
          clothlab::collision_response(r, Vec3(3.0, -2.0, 4.0), n, 0.01, 0.5, 0.2, 0.1);
      // What the usual slips give here is worked out in slips.hpp (kDynamicFriction).
      INFO(grading::hint(s.v, grading::slips::kDynamicFriction, 1e-12,
                         "a 5 m/s slide is past the static limit: dynamic friction slows it by "
                         "exactly mu_d j = 0.1 * 3 = 0.3 m/s and keeps its direction, v_t' = v_t "
                         "(1 - mu_d j / |v_t|)"));
      CHECK_NEAR_VEC(s.v, Vec3(2.82, 1.0, 3.76), 1e-12);
    }
  }

  TEST_CASE("ex05.1 friction never adds energy nor speeds up or reverses the slide" * POINTS(1)) {
    // For any v with v . n < 0: |v'|^2 = e^2 (v . n)^2 + |v_t'|^2, and with 0 <= e <= 1 and
    // |v_t'| <= |v_t| this is at most (v . n)^2 + |v_t|^2 = |v|^2: a collision only takes
    // energy out. Friction acts against the slide: v_t' is zero or points along v_t
    // (v_t' . v_t >= 0), and never longer than v_t. The normal part leaves as -e (v . n).
    for (const Contact& c : kContacts) {
      INFO(describe(c));
      const Vec3 n = c.n.normalized();
      const clothlab::PointState s =
          clothlab::collision_response(Vec3(0.1, 0.2, 0.3), c.v, n, 0.05, c.e, c.mu_s, c.mu_d);
      const Vec3 t_in = c.v - c.v.dot(n) * n;
      const Vec3 t_out = s.v - s.v.dot(n) * n;
      CAPTURE(s.v);
      {
        INFO(
            "the normal part must leave as v' . n = -e (v . n): split v along the normal n with "
            "one dot product, not along y");
        CHECK(s.v.dot(n) == doctest::Approx(-c.e * c.v.dot(n)).epsilon(1e-12).scale(1.0));
      }
      {
        INFO("a collision must never speed a particle up: |v'| <= |v|");
        CHECK(s.v.norm() <= c.v.norm() * (1.0 + 1e-12));
      }
      {
        INFO(
            "friction must never speed up the slide (|v_t'| <= |v_t|) nor reverse it "
            "(v_t' . v_t >= 0): dynamic friction must not reverse the slide, so a slide within "
            "mu_s j sticks (v_t' = 0) instead of going through the dynamic formula");
        CHECK(t_out.norm() <= t_in.norm() * (1.0 + 1e-12));
        CHECK(t_out.dot(t_in) >= -1e-12);
      }
    }
  }

  TEST_CASE("ex05.1 a particle already moving out is moved out but keeps its velocity" *
            POINTS(1)) {
    // Ground normal n = (0, 1, 0), 0.05 m deep at r = (1, -0.05, 2): r' = (1, 0, 2) in every
    // case. With v . n >= 0 there is no approach, so no bounce and no impulse (j would be 0),
    // hence no friction either, however large mu_s and mu_d: v' = v.
    const Vec3 r(1.0, -0.05, 2.0), n(0.0, 1.0, 0.0);
    {
      // Leaving at v = (2, 1.5, -1): v . n = 1.5 > 0.
      const Vec3 v(2.0, 1.5, -1.0);
      const clothlab::PointState s = clothlab::collision_response(r, v, n, 0.05, 0.5, 0.8, 0.8);
      INFO(
          "a particle already moving out (v . n > 0) is still put back on the surface, but its "
          "velocity must stay as it is: no reflection, and friction only during a bounce (the "
          "impulse j = (1 + e) |v . n| exists only when v . n < 0)");
      CHECK_NEAR_VEC(s.r, Vec3(1.0, 0.0, 2.0), 1e-12);
      CHECK_NEAR_VEC(s.v, v, 0.0);
    }
    {
      // Sliding exactly along the surface, v = (2, 0, -1): v . n = 0, no approach either.
      const Vec3 v(2.0, 0.0, -1.0);
      const clothlab::PointState s = clothlab::collision_response(r, v, n, 0.05, 0.5, 0.8, 0.8);
      INFO(
          "a particle sliding along the surface (v . n = 0) gets no impulse, so no friction: "
          "its velocity must be unchanged");
      CHECK_NEAR_VEC(s.r, Vec3(1.0, 0.0, 2.0), 1e-12);
      CHECK_NEAR_VEC(s.v, v, 0.0);
    }
  }

  TEST_CASE("ex05.1 on a tilted surface the bounce works along its normal" * POINTS(1)) {
    // A unit sphere at the origin; the particle is found 0.1 m inside it where the outward
    // normal is n = (0.6, 0.8, 0): r = 0.9 n = (0.54, 0.72, 0), r' = r + 0.1 n = (0.6, 0.8, 0),
    // on the surface. It falls straight down at v = (0, -5, 0):
    //   v . n = -4, v_n = -4 n = (-2.4, -3.2, 0), v_t = v - v_n = (2.4, -1.8, 0), |v_t| = 3.
    // e = 0.5: v_n' = -0.5 v_n = (1.2, 1.6, 0).
    const Vec3 n(0.6, 0.8, 0.0), r(0.54, 0.72, 0.0), v(0.0, -5.0, 0.0);
    {
      // No friction: v' = (1.2, 1.6, 0) + (2.4, -1.8, 0) = (3.6, -0.2, 0). (Reflecting v.y
      // instead would give (0, 2.5, 0).)
      const clothlab::PointState s = clothlab::collision_response(r, v, n, 0.1, 0.5, 0.0, 0.0);
      INFO(
          "the normal part is (v . n) n, not v.y: on a sphere the normal (0.6, 0.8, 0) is "
          "tilted, so a vertical fall bounces off sideways, v' = -e v_n + v_t");
      CHECK_NEAR_VEC(s.r, Vec3(0.6, 0.8, 0.0), 1e-12);
      CHECK_NEAR_VEC(s.v, Vec3(3.6, -0.2, 0.0), 1e-12);
    }
    {
      // mu_s = 0.3, mu_d = 0.2: j = (1 + 0.5) * 4 = 6, mu_s j = 1.8 < 3, so it slides;
      // v_t' = v_t (1 - 0.2 * 6 / 3) = 0.6 v_t = (1.44, -1.08, 0),
      // v' = (1.2 + 1.44, 1.6 - 1.08, 0) = (2.64, 0.52, 0).
      const clothlab::PointState s = clothlab::collision_response(r, v, n, 0.1, 0.5, 0.3, 0.2);
      INFO(
          "friction acts on the part of v across the normal, v_t = v - (v . n) n, with the "
          "impulse j = (1 + e) |v . n| = 6 m/s: a 3 m/s slide loses mu_d j = 1.2 m/s");
      CHECK_NEAR_VEC(s.v, Vec3(2.64, 0.52, 0.0), 1e-12);
    }
  }

}  // TEST_SUITE("ex05")
