// Grading tests for lesson 09, ropes and soft solids (exercise ex09.1, strain limiting).
//
// Every expected value is worked out in the comment beside it, from the lesson's equations;
// none comes from the reference solution. With e* = r2 - r1, l = |e*|, e = e* / l, w = w1 + w2:
//   target = (1 + max_strain) l0 past the stretch limit, (1 - max_compression) l0 past the
//   compression limit; C = l - target; dr1 = +w1/w C e; dr2 = -w2/w C e.
// The numbers are chosen so that lengths come out whole: e* = (6, 0, 8) has l = 10 and
// e = (0.6, 0, 0.8).
#include <array>
#include <cmath>

#include "clothlab/after_step/strain_limiting.hpp"
#include "grading.hpp"

using clothlab::StrainCorrection;
using clothlab::StrainLimits;
using clothlab::Vec3;

namespace {

bool finite(const Vec3& a) {
  return a.allFinite();
}

}  // namespace

TEST_SUITE("ex09") {
  TEST_CASE("ex09.1 a spring within its limits is left exactly where it is" * POINTS(1)) {
    // l0 = 4 and max_strain = 0.25: the longest allowed length is (1 + 0.25) 4 = 5.
    // max_compression = 1 (the default) allows any length down to (1 - 1) 4 = 0: no lower limit.
    const StrainLimits stretch_only{0.25, 1.0};
    const Vec3 r1(1.0, 2.0, 3.0);
    {
      // l = 4.5: stretched, but by 12.5 % < 25 %. Nothing to correct: both moves exactly zero.
      const StrainCorrection c = clothlab::strain_limit_correction(r1, r1 + Vec3(0.0, 4.5, 0.0),
                                                                   1.0, 1.0, 4.0, stretch_only);
      INFO(
          "r1 = (1, 2, 3), r2 = r1 + (0, 4.5, 0), w1 = w2 = 1, l0 = 4, max_strain = 0.25: the "
          "spring is 4.5 long, within its limit 5, and must not move (hint 1); got dr1 = "
          << grading::show(c.dr1) << ", dr2 = " << grading::show(c.dr2));
      CHECK(c.dr1 == Vec3::Zero());
      CHECK(c.dr2 == Vec3::Zero());
    }
    {
      // l = 5 exactly (e* = (3, 0, 4)): at the limit, not past it.
      const StrainCorrection c = clothlab::strain_limit_correction(r1, r1 + Vec3(3.0, 0.0, 4.0),
                                                                   1.0, 1.0, 4.0, stretch_only);
      INFO("a spring exactly at its limit, l = (1 + max_strain) l0 = 5, is within it; got dr1 = "
           << grading::show(c.dr1) << ", dr2 = " << grading::show(c.dr2));
      CHECK(c.dr1.norm() <= 1e-12);
      CHECK(c.dr2.norm() <= 1e-12);
    }
    {
      // l = 1, squeezed to a quarter of l0 = 4. With max_compression = 1 there is no lower
      // limit: a stretch-only limit leaves compressed springs alone.
      const StrainCorrection c = clothlab::strain_limit_correction(r1, r1 + Vec3(0.0, 0.0, 1.0),
                                                                   1.0, 1.0, 4.0, stretch_only);
      INFO(
          "with max_compression = 1 the shortest allowed length is (1 - 1) l0 = 0, so a "
          "compressed spring (l = 1, l0 = 4) must not move: only springs past a limit are "
          "corrected, and the target is never simply l0 (hint 2); got dr1 = "
          << grading::show(c.dr1) << ", dr2 = " << grading::show(c.dr2));
      CHECK(c.dr1 == Vec3::Zero());
      CHECK(c.dr2 == Vec3::Zero());
    }
    {
      // Past the limit it is corrected: l = 5.5 along y, C = 5.5 - 5 = 0.5, e = (0, 1, 0), and
      // with w1 = 1.5, w2 = 0.5 the shares are 3/4 and 1/4: dr1 = (0, 0.375, 0),
      // dr2 = (0, -0.125, 0).
      const StrainCorrection c = clothlab::strain_limit_correction(r1, r1 + Vec3(0.0, 5.5, 0.0),
                                                                   1.5, 0.5, 4.0, stretch_only);
      INFO(
          "a spring 5.5 long, past its limit 5, must be pulled back to it: dr1 = (0, 0.375, 0), "
          "dr2 = (0, -0.125, 0); got dr1 = "
          << grading::show(c.dr1) << ", dr2 = " << grading::show(c.dr2));
      CHECK_NEAR_VEC(c.dr1, Vec3(0.0, 0.375, 0.0), 1e-12);
      CHECK_NEAR_VEC(c.dr2, Vec3(0.0, -0.125, 0.0), 1e-12);
    }
  }

  TEST_CASE("ex09.1 a stretched spring between equal masses worked by hand" * POINTS(2)) {
    // r1 = 0, r2 = (6, 0, 8): l = 10, e = (0.6, 0, 0.8). l0 = 4, max_strain = 0.25: the limit is
    // 5, so C = 10 - 5 = 5. Equal masses, w1 = w2 = 2: each end takes half,
    //   dr1 = +1/2 * 5 * (0.6, 0, 0.8) = (1.5, 0, 2),   dr2 = (-1.5, 0, -2),
    // and the spring ends 5 long: r1' = (1.5, 0, 2), r2' = (4.5, 0, 6), |r2' - r1'| = |(3, 0, 4)|.
    // (Correcting to l0 would give C = 6 and dr1 = (1.8, 0, 2.4).)
    const Vec3 r1 = Vec3::Zero(), r2(6.0, 0.0, 8.0);
    const StrainCorrection c =
        clothlab::strain_limit_correction(r1, r2, 2.0, 2.0, 4.0, StrainLimits{0.25, 1.0});
    INFO(
        "r1 = (0, 0, 0), r2 = (6, 0, 8), w1 = w2 = 2 1/kg, l0 = 4 m, max_strain = 0.25: "
        "l = 10, target (1 + 0.25) 4 = 5, C = 5, e = (0.6, 0, 0.8)");
    {
      INFO(
          "particle 1 moves toward particle 2 by w1 / (w1 + w2) C e = (1.5, 0, 2) (hints 2 "
          "and 4)");
      CHECK_NEAR_VEC(c.dr1, Vec3(1.5, 0.0, 2.0), 1e-12);
    }
    {
      INFO("particle 2 moves toward particle 1 by -w2 / (w1 + w2) C e = (-1.5, 0, -2)");
      CHECK_NEAR_VEC(c.dr2, Vec3(-1.5, 0.0, -2.0), 1e-12);
    }
    {
      const double l_new = ((r2 + c.dr2) - (r1 + c.dr1)).norm();
      INFO(
          "after the correction the spring must be exactly at its limit, 5, neither at l0 = 4 "
          "nor still stretched; it is "
          << l_new);
      CHECK(l_new == doctest::Approx(5.0).epsilon(1e-12));
    }
  }

  TEST_CASE("ex09.1 the correction is split by inverse mass" * POINTS(1)) {
    // The same spring, l = 10, limit 5, C = 5, e = (0.6, 0, 0.8), now with w1 = 3 and w2 = 1
    // (particle 1 three times lighter). Shares 3/4 and 1/4:
    //   dr1 = 3/4 * 5 e = 3.75 e = (2.25, 0, 3),   dr2 = -1/4 * 5 e = -1.25 e = (-0.75, 0, -1).
    // Momentum: m1 dr1 + m2 dr2 = (1/3) (2.25, 0, 3) + (-0.75, 0, -1) = 0.
    const StrainCorrection c = clothlab::strain_limit_correction(
        Vec3::Zero(), Vec3(6.0, 0.0, 8.0), 3.0, 1.0, 4.0, StrainLimits{0.25, 1.0});
    // What the usual slips give is worked out in slips.hpp (kStrainShare).
    INFO(grading::hint(
        c.dr1, grading::slips::kStrainShare, 1e-9,
        "r1 = (0, 0, 0), r2 = (6, 0, 8), w1 = 3, w2 = 1, l0 = 4, max_strain = 0.25: C = 5; "
        "the lighter particle 1 takes the share w1 / (w1 + w2) = 3/4 (hint 3)"));
    CHECK_NEAR_VEC(c.dr1, Vec3(2.25, 0.0, 3.0), 1e-12);
    CHECK_NEAR_VEC(c.dr2, Vec3(-0.75, 0.0, -1.0), 1e-12);
    {
      const Vec3 momentum = c.dr1 / 3.0 + c.dr2 / 1.0;
      INFO("the centre of mass must not move: m1 dr1 + m2 dr2 = dr1 / w1 + dr2 / w2 = 0, got "
           << grading::show(momentum));
      CHECK(momentum.norm() <= 1e-12);
    }
  }

  TEST_CASE("ex09.1 a pinned end never moves" * POINTS(1)) {
    // w1 = 0: particle 1 is pinned and takes the share 0 / (0 + 2) = 0; particle 2 takes all of
    // C = 5: dr2 = -5 e = (-3, 0, -4), and the spring ends at length 5.
    const StrainLimits limits{0.25, 1.0};
    const StrainCorrection c =
        clothlab::strain_limit_correction(Vec3::Zero(), Vec3(6.0, 0.0, 8.0), 0.0, 2.0, 4.0, limits);
    {
      // What the usual slips give is worked out in slips.hpp (kStrainPinned).
      INFO(grading::hint(
          c.dr1, grading::slips::kStrainPinned, 1e-9,
          "r1 = (0, 0, 0) pinned (w1 = 0), r2 = (6, 0, 8), w2 = 2, l0 = 4, max_strain = 0.25: "
          "the pinned end must stay exactly where it is (hint 3); got dr1 = " +
              grading::show(c.dr1)));
      CHECK(c.dr1 == Vec3::Zero());
    }
    {
      INFO(
          "the free end takes the whole correction, -C e = (-3, 0, -4), and the spring ends "
          "at its limit 5");
      CHECK_NEAR_VEC(c.dr2, Vec3(-3.0, 0.0, -4.0), 1e-12);
    }
    {
      // The same with the other end pinned: dr1 = +5 e = (3, 0, 4), dr2 = 0.
      const StrainCorrection d = clothlab::strain_limit_correction(
          Vec3::Zero(), Vec3(6.0, 0.0, 8.0), 2.0, 0.0, 4.0, limits);
      INFO("with particle 2 pinned (w2 = 0) particle 1 moves the whole way, (3, 0, 4); got dr1 = "
           << grading::show(d.dr1) << ", dr2 = " << grading::show(d.dr2));
      CHECK_NEAR_VEC(d.dr1, Vec3(3.0, 0.0, 4.0), 1e-12);
      CHECK(d.dr2 == Vec3::Zero());
    }
    {
      // Both pinned: w1 + w2 = 0, no share is defined and nothing may move. 0 / 0 would be NaN.
      const StrainCorrection d = clothlab::strain_limit_correction(
          Vec3::Zero(), Vec3(6.0, 0.0, 8.0), 0.0, 0.0, 4.0, limits);
      INFO(
          "a spring between two pinned particles cannot be corrected: both moves must be "
          "exactly zero, not NaN from 0 / (0 + 0) (hint 1); got dr1 = "
          << grading::show(d.dr1) << ", dr2 = " << grading::show(d.dr2));
      CHECK(d.dr1 == Vec3::Zero());
      CHECK(d.dr2 == Vec3::Zero());
    }
  }

  TEST_CASE("ex09.1 a squeezed spring is pushed back out to its compression limit" * POINTS(1)) {
    // l0 = 4, max_compression = 0.2: the shortest allowed length is (1 - 0.2) 4 = 3.2.
    // r1 = (1, 1, 1), r2 = r1 + (1.2, 0, 1.6): l = 2, e = (0.6, 0, 0.8), C = 2 - 3.2 = -1.2.
    // Equal masses: dr1 = 1/2 (-1.2) e = -0.6 e = (-0.36, 0, -0.48) (away from particle 2),
    // dr2 = +0.6 e = (0.36, 0, 0.48); the spring ends 3.2 long.
    const Vec3 r1(1.0, 1.0, 1.0), r2 = r1 + Vec3(1.2, 0.0, 1.6);
    const StrainCorrection c =
        clothlab::strain_limit_correction(r1, r2, 1.0, 1.0, 4.0, StrainLimits{0.25, 0.2});
    INFO(
        "r1 = (1, 1, 1), r2 = r1 + (1.2, 0, 1.6), w1 = w2 = 1, l0 = 4, max_strain = 0.25, "
        "max_compression = 0.2: l = 2 is below (1 - 0.2) 4 = 3.2, C = l - 3.2 = -1.2, and the "
        "ends move apart: dr1 = -0.6 e, dr2 = +0.6 e with e = (0.6, 0, 0.8)");
    CHECK_NEAR_VEC(c.dr1, Vec3(-0.36, 0.0, -0.48), 1e-12);
    CHECK_NEAR_VEC(c.dr2, Vec3(0.36, 0.0, 0.48), 1e-12);
    const double l_new = ((r2 + c.dr2) - (r1 + c.dr1)).norm();
    INFO("the spring must end at its compression limit 3.2, not at l0 = 4; it is " << l_new);
    CHECK(l_new == doctest::Approx(3.2).epsilon(1e-12));
  }

  TEST_CASE("ex09.1 coincident ends give no correction and no NaN" * POINTS(1)) {
    // r1 = r2: l = 0 and e = e* / l = 0 / 0 has no direction. With max_compression = 0.5 the
    // spring is past its compression limit (0 < 2), yet there is no way to say where to push:
    // both moves zero, and finite. Springs of a cloth do meet like this (a fold pressed flat).
    const Vec3 r(0.5, -1.0, 2.0);
    const StrainCorrection c =
        clothlab::strain_limit_correction(r, r, 1.0, 1.0, 4.0, StrainLimits{0.1, 0.5});
    INFO(
        "r1 = r2 = (0.5, -1, 2), w1 = w2 = 1, l0 = 4, max_compression = 0.5: with l = 0 there "
        "is no direction e to move along; return the zero correction before dividing by l "
        "(hint 1); got dr1 = "
        << grading::show(c.dr1) << ", dr2 = " << grading::show(c.dr2));
    CHECK(finite(c.dr1));
    CHECK(finite(c.dr2));
    CHECK(c.dr1 == Vec3::Zero());
    CHECK(c.dr2 == Vec3::Zero());
    // Only l == 0 is special: 1 mm apart along e = (0.6, 0, 0.8) the spring is past its limit
    // 2, C = 0.001 - 2 = -1.999, and w1 = 1, w2 = 3 give dr1 = 1/4 C e = -0.49975 e =
    // (-0.29985, 0, -0.3998), dr2 = -3/4 C e = 1.49925 e = (0.89955, 0, 1.1994).
    const StrainCorrection near = clothlab::strain_limit_correction(
        r, r + 0.001 * Vec3(0.6, 0.0, 0.8), 1.0, 3.0, 4.0, StrainLimits{0.1, 0.5});
    INFO("ends 1 mm apart are pushed apart to the compression limit 2; got dr1 = "
         << grading::show(near.dr1) << ", dr2 = " << grading::show(near.dr2));
    CHECK_NEAR_VEC(near.dr1, Vec3(-0.29985, 0.0, -0.3998), 1e-10);
    CHECK_NEAR_VEC(near.dr2, Vec3(0.89955, 0.0, 1.1994), 1e-10);
  }

  TEST_CASE("ex09.1 one correction lands on the limit along the spring for any spring" *
            POINTS(1)) {
    // Invariants of the correction, over springs in many directions, lengths, rest lengths and
    // masses: the new length is the limit that was passed; both moves are along e (their cross
    // product with e* is zero); the centre of mass m1 r1 + m2 r2 stays (dr1 / w1 + dr2 / w2 = 0);
    // and the shares add up, dr1 - dr2 = C e.
    const std::array<Vec3, 4> directions = {Vec3(1.0, 0.0, 0.0), Vec3(0.0, -1.0, 0.0),
                                            Vec3(2.0, -3.0, 6.0) / 7.0, Vec3(-1.0, 4.0, 8.0) / 9.0};
    const std::array<double, 3> rests = {0.05, 1.0, 3.0};                  // l0 [m]
    const std::array<double, 6> ratios = {0.1, 0.5, 0.79, 1.0, 1.3, 2.5};  // l / l0
    const std::array<std::array<double, 2>, 3> masses = {{{1.0, 1.0}, {5.0, 0.5}, {0.2, 7.0}}};
    const StrainLimits limits{0.1, 0.2};  // allowed: 0.8 l0 <= l <= 1.1 l0
    const Vec3 r1(0.3, 2.0, -1.0);
    for (const Vec3& d : directions) {
      for (double l0 : rests) {
        for (double ratio : ratios) {
          for (const auto& w : masses) {
            const Vec3 r2 = r1 + ratio * l0 * d;
            const StrainCorrection c =
                clothlab::strain_limit_correction(r1, r2, w[0], w[1], l0, limits);
            const double l_new = ((r2 + c.dr2) - (r1 + c.dr1)).norm();
            // Within [0.8, 1.1] l0 the length stays; past it, it lands on the nearer limit.
            const double expected = ratio > 1.1 ? 1.1 * l0 : ratio < 0.8 ? 0.8 * l0 : ratio * l0;
            const bool lands = std::abs(l_new - expected) <= 1e-9 * expected;
            const bool along = c.dr1.cross(d).norm() <= 1e-12 * l0 &&  // d is e, a unit vector
                               c.dr2.cross(d).norm() <= 1e-12 * l0;
            const bool centred =
                (c.dr1 / w[0] + c.dr2 / w[1]).norm() <= 1e-9 * l0 * (1.0 / w[0] + 1.0 / w[1]);
            if (lands && along && centred) continue;
            // The first spring that fails is reported, not every one of the 216.
            INFO("r1 = " << grading::show(r1) << ", r2 = " << grading::show(r2) << ", w1 = " << w[0]
                         << ", w2 = " << w[1] << ", l0 = " << l0
                         << ", max_strain = 0.1, max_compression = 0.2: got dr1 = "
                         << grading::show(c.dr1) << ", dr2 = " << grading::show(c.dr2));
            {
              INFO("the new length must be " << expected << " (the limit passed, or the length "
                                             << "itself within the limits); it is " << l_new);
              CHECK(lands);
            }
            {
              INFO("both ends must move along the spring, parallel to e = (r2 - r1) / l");
              CHECK(along);
            }
            {
              INFO(
                  "the centre of mass must stay: dr1 / w1 + dr2 / w2 = 0 (split by inverse "
                  "mass, hint 3)");
              CHECK(centred);
            }
            return;
          }
        }
      }
    }
  }
}
