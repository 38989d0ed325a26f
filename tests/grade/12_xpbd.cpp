// Grading tests for lesson 12, position-based dynamics and XPBD (exercise ex12.1, one projection
// of a distance constraint).
//
// Every expected value is worked out in the comment beside it, from the lesson's equations;
// none comes from the reference solution. With d = x_i - x_j, l = |d|, n = d / l, C = l - l0:
//   delta_lambda = (-C - alpha_tilde lambda) / (w_i + w_j + alpha_tilde),
//   x_i += w_i delta_lambda n,   x_j -= w_j delta_lambda n.
// The numbers are chosen so that every value comes out as a short fraction: d = (0, -3, -4) has
// l = 5 and n = (0, -0.6, -0.8).
#include <cmath>
#include <sstream>
#include <string>

#include "clothlab/integrators/xpbd.hpp"
#include "grading.hpp"

using clothlab::Vec3;

namespace {

// One projection; x_i and x_j are moved, the returned delta_lambda kept in `dl`.
struct Projected {
  Vec3 x_i, x_j;
  double dl;
};
Projected project(Vec3 x_i, Vec3 x_j, double w_i, double w_j, double l0, double alpha_tilde,
                  double lambda) {
  const double dl = clothlab::xpbd_distance_projection(x_i, x_j, w_i, w_j, l0, alpha_tilde, lambda);
  return {x_i, x_j, dl};
}

}  // namespace

TEST_SUITE("ex12") {
  TEST_CASE("ex12.1 a constraint at its rest length moves nothing" * POINTS(1)) {
    // x_j - x_i = (0, 3, 4): l = 5 = l0, so C = 0; with lambda = 0 the numerator -C - alpha_tilde
    // lambda is 0: delta_lambda = 0 and no correction, whatever the masses and the compliance.
    const Vec3 x_i(1.0, 2.0, 3.0), x_j(1.0, 5.0, 7.0);
    const Projected p = project(x_i, x_j, 1.0, 2.0, 5.0, 0.5, 0.0);
    INFO(
        "x_i = (1, 2, 3), x_j = (1, 5, 7), l0 = 5, w_i = 1, w_j = 2, alpha_tilde = 0.5, "
        "lambda = 0: C = 0, nothing to correct; got delta_lambda = "
        << p.dl << ", x_i = " << grading::show(p.x_i) << ", x_j = " << grading::show(p.x_j));
    CHECK(std::abs(p.dl) <= 1e-12);
    CHECK((p.x_i - x_i).norm() <= 1e-12);
    CHECK((p.x_j - x_j).norm() <= 1e-12);
    // With l0 = 4.5 the same pair is 0.5 too long: n = (x_i - x_j) / l = (0, -0.6, -0.8),
    // delta_lambda = -0.5 / (1 + 2 + 0.5) = -1/7; x_i += 1 (-1/7) n = (0, 0.6, 0.8) / 7,
    // x_j -= 2 (-1/7) n, that is by (0, -1.2, -1.6) / 7.
    const Projected q = project(x_i, x_j, 1.0, 2.0, 4.5, 0.5, 0.0);
    INFO("the same pair with l0 = 4.5 is stretched by 0.5: delta_lambda = -0.5 / 3.5 = -1/7; got "
         << q.dl << ", x_i = " << grading::show(q.x_i) << ", x_j = " << grading::show(q.x_j));
    CHECK(q.dl == doctest::Approx(-1.0 / 7.0).epsilon(1e-12));
    CHECK_NEAR_VEC(q.x_i, Vec3(x_i + Vec3(0.0, 0.6, 0.8) / 7.0), 1e-12);
    CHECK_NEAR_VEC(q.x_j, Vec3(x_j + Vec3(0.0, -1.2, -1.6) / 7.0), 1e-12);
  }

  TEST_CASE("ex12.1 a stretched and a squeezed pair of equal masses worked by hand" * POINTS(2)) {
    {
      // x_i = 0, x_j = (2, 0, 0): l = 2, n = (-1, 0, 0), C = 2 - 1 = 1. Rigid (alpha_tilde = 0),
      // w_i = w_j = 1: delta_lambda = -1 / 2. x_i += 1 (-1/2) (-1, 0, 0) = (0.5, 0, 0),
      // x_j -= 1 (-1/2) (-1, 0, 0), to (1.5, 0, 0): the pair ends exactly l0 = 1 apart.
      const Projected p = project(Vec3::Zero(), Vec3(2.0, 0.0, 0.0), 1.0, 1.0, 1.0, 0.0, 0.0);
      INFO(
          "x_i = (0, 0, 0), x_j = (2, 0, 0), l0 = 1, w_i = w_j = 1, alpha_tilde = 0, lambda = "
          "0: C = 1, n = (x_i - x_j) / l = (-1, 0, 0), delta_lambda = -C / (w_i + w_j) = -0.5 "
          "(hint 3); got "
          << p.dl);
      CHECK(p.dl == doctest::Approx(-0.5).epsilon(1e-12));
      CHECK_NEAR_VEC(p.x_i, Vec3(0.5, 0.0, 0.0), 1e-12);
      CHECK_NEAR_VEC(p.x_j, Vec3(1.5, 0.0, 0.0), 1e-12);
    }
    {
      // x_j = (0.5, 0, 0): l = 0.5, C = -0.5, n = (-1, 0, 0); delta_lambda = 0.5 / 2 = 0.25 > 0.
      // x_i += 0.25 (-1, 0, 0) -> (-0.25, 0, 0); x_j -= 0.25 (-1, 0, 0) -> (0.75, 0, 0): pushed
      // apart to l0 = 1.
      const Projected p = project(Vec3::Zero(), Vec3(0.5, 0.0, 0.0), 1.0, 1.0, 1.0, 0.0, 0.0);
      INFO(
          "x_i = (0, 0, 0), x_j = (0.5, 0, 0), l0 = 1, w_i = w_j = 1, alpha_tilde = 0: a "
          "squeezed pair, C = -0.5, delta_lambda = +0.25, the ends pushed apart; got "
          << p.dl);
      CHECK(p.dl == doctest::Approx(0.25).epsilon(1e-12));
      CHECK_NEAR_VEC(p.x_i, Vec3(-0.25, 0.0, 0.0), 1e-12);
      CHECK_NEAR_VEC(p.x_j, Vec3(0.75, 0.0, 0.0), 1e-12);
    }
  }

  TEST_CASE("ex12.1 the correction is split by inverse mass" * POINTS(1)) {
    // x_i = (1, 2, 3), x_j = (1, 5, 7): d = (0, -3, -4), l = 5, n = (0, -0.6, -0.8); l0 = 3, so
    // C = 2. w_i = 3, w_j = 1, rigid: delta_lambda = -2 / 4 = -0.5.
    //   x_i += 3 (-0.5) n = -1.5 n = (0, 0.9, 1.2)   -> (1, 2.9, 4.2)
    //   x_j -= 1 (-0.5) n = +0.5 n = (0, -0.3, -0.4) -> (1, 4.7, 6.6)
    // New length |(0, 1.8, 2.4)| = 3 = l0; the lighter end moved three times as far, and
    // m_i dx_i + m_j dx_j = (1/3) (0, 0.9, 1.2) + (0, -0.3, -0.4) = 0.
    const Projected p = project(Vec3(1.0, 2.0, 3.0), Vec3(1.0, 5.0, 7.0), 3.0, 1.0, 3.0, 0.0, 0.0);
    INFO(
        "x_i = (1, 2, 3), x_j = (1, 5, 7), l0 = 3, w_i = 3, w_j = 1, alpha_tilde = 0: C = 2, "
        "n = (0, -0.6, -0.8), delta_lambda = -0.5; each end moves by its own w times "
        "delta_lambda; got delta_lambda = "
        << p.dl);
    CHECK(p.dl == doctest::Approx(-0.5).epsilon(1e-12));
    CHECK_NEAR_VEC(p.x_i, Vec3(1.0, 2.9, 4.2), 1e-12);
    CHECK_NEAR_VEC(p.x_j, Vec3(1.0, 4.7, 6.6), 1e-12);
    const Vec3 momentum = (p.x_i - Vec3(1.0, 2.0, 3.0)) / 3.0 + (p.x_j - Vec3(1.0, 5.0, 7.0));
    INFO("the centre of mass must not move: dx_i / w_i + dx_j / w_j = 0, got "
         << grading::show(momentum));
    CHECK(momentum.norm() <= 1e-12);
  }

  TEST_CASE("ex12.1 a pinned end never moves and coincident ends move nothing" * POINTS(1)) {
    {
      // x_i = 0 pinned (w_i = 0), x_j = (0, -1.5, 0), l0 = 1: n = (0, 1, 0), C = 0.5,
      // delta_lambda = -0.5 / (0 + 1) = -0.5; x_j -= 1 (-0.5) (0, 1, 0), to (0, -1, 0).
      const Projected p = project(Vec3::Zero(), Vec3(0.0, -1.5, 0.0), 0.0, 1.0, 1.0, 0.0, 0.0);
      INFO(
          "x_i = (0, 0, 0) pinned (w_i = 0), x_j = (0, -1.5, 0), w_j = 1, l0 = 1: the pinned "
          "end stays exactly, the free one takes the whole correction to (0, -1, 0); got x_i = "
          << grading::show(p.x_i) << ", x_j = " << grading::show(p.x_j));
      CHECK(p.x_i == Vec3::Zero());
      CHECK_NEAR_VEC(p.x_j, Vec3(0.0, -1.0, 0.0), 1e-12);
      CHECK(p.dl == doctest::Approx(-0.5).epsilon(1e-12));
    }
    {
      // Both pinned and rigid: w_i + w_j + alpha_tilde = 0, and delta_lambda would be
      // -C / 0 = -0.5 / 0 = -infinity (0 / 0, NaN, for a pair at its rest length).
      const Projected p = project(Vec3::Zero(), Vec3(0.0, -1.5, 0.0), 0.0, 0.0, 1.0, 0.0, 0.0);
      INFO(
          "both ends pinned (w_i = w_j = 0), alpha_tilde = 0: nothing can move; return 0 "
          "before dividing (hint 1); got delta_lambda = "
          << p.dl << ", x_i = " << grading::show(p.x_i) << ", x_j = " << grading::show(p.x_j));
      CHECK(p.dl == 0.0);
      CHECK(p.x_i == Vec3::Zero());
      CHECK(p.x_j == Vec3(0.0, -1.5, 0.0));
    }
    {
      // Coincident ends: l = 0 and n = d / l has no direction.
      const Vec3 x(0.5, -1.0, 2.0);
      const Projected p = project(x, x, 1.0, 1.0, 1.0, 0.0, 0.0);
      INFO(
          "x_i = x_j = (0.5, -1, 2): no direction n to move along; return 0 and move nothing, "
          "never NaN (hint 1); got delta_lambda = "
          << p.dl << ", x_i = " << grading::show(p.x_i) << ", x_j = " << grading::show(p.x_j));
      CHECK(p.dl == 0.0);
      CHECK(p.x_i == x);
      CHECK(p.x_j == x);
    }
  }

  TEST_CASE("ex12.1 compliance: alpha_tilde = 0 is rigid and alpha_tilde > 0 gives way" *
            POINTS(1)) {
    // The stretched pair of equal masses again, C = 1, w_i + w_j = 2, n = (-1, 0, 0).
    //   alpha_tilde = 0: delta_lambda = -1/2, the pair ends at l0 = 1 (the whole correction).
    //   alpha_tilde = 2: delta_lambda = -1 / (2 + 2) = -1/4, each end moves 1/4: x_i ->
    //   (0.25, 0, 0), x_j -> (1.75, 0, 0), length 1.5 (half the correction).
    const Projected rigid = project(Vec3::Zero(), Vec3(2.0, 0.0, 0.0), 1.0, 1.0, 1.0, 0.0, 0.0);
    const Projected soft = project(Vec3::Zero(), Vec3(2.0, 0.0, 0.0), 1.0, 1.0, 1.0, 2.0, 0.0);
    INFO(
        "x_i = (0, 0, 0), x_j = (2, 0, 0), l0 = 1, w_i = w_j = 1, lambda = 0: alpha_tilde = 0 "
        "must close the whole gap (length 1), alpha_tilde = 2 must close half of it "
        "(delta_lambda = -C / (w_i + w_j + alpha_tilde) = -0.25, length 1.5); got lengths "
        << (rigid.x_j - rigid.x_i).norm() << " and " << (soft.x_j - soft.x_i).norm());
    CHECK((rigid.x_j - rigid.x_i).norm() == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(soft.dl == doctest::Approx(-0.25).epsilon(1e-12));
    CHECK_NEAR_VEC(soft.x_i, Vec3(0.25, 0.0, 0.0), 1e-12);
    CHECK_NEAR_VEC(soft.x_j, Vec3(1.75, 0.0, 0.0), 1e-12);
  }

  TEST_CASE("ex12.1 lambda accumulates over two iterations" * POINTS(2)) {
    // w_i = w_j = 1, alpha_tilde = 1, x_i = 0, x_j = (2, 0, 0), l0 = 1, n = (-1, 0, 0).
    // Iteration 1, lambda = 0: C = 1, delta_lambda = -1 / 3; x_i -> (1/3, 0, 0),
    //   x_j -> (5/3, 0, 0), length 4/3; lambda = -1/3.
    // Iteration 2, lambda = -1/3: C = 1/3, delta_lambda = (-1/3 - 1 (-1/3)) / 3 = 0: the
    //   constraint already balances its compliance, C = -alpha_tilde lambda, and nothing moves.
    // Without the term -alpha_tilde lambda (plain PBD) it would be -1/9, and every further
    // iteration would pull the pair closer: the stiffness would depend on the iterations.
    Vec3 x_i = Vec3::Zero(), x_j(2.0, 0.0, 0.0);
    double lambda = 0.0;
    const double dl1 = clothlab::xpbd_distance_projection(x_i, x_j, 1.0, 1.0, 1.0, 1.0, lambda);
    lambda += dl1;
    {
      INFO(
          "iteration 1 of x_i = (0, 0, 0), x_j = (2, 0, 0), l0 = 1, w_i = w_j = 1, "
          "alpha_tilde = 1, lambda = 0: delta_lambda = -C / (w_i + w_j + alpha_tilde) = -1/3; "
          "got "
          << dl1);
      CHECK(dl1 == doctest::Approx(-1.0 / 3.0).epsilon(1e-12));
      CHECK_NEAR_VEC(x_i, Vec3(1.0 / 3.0, 0.0, 0.0), 1e-12);
      CHECK_NEAR_VEC(x_j, Vec3(5.0 / 3.0, 0.0, 0.0), 1e-12);
    }
    const double dl2 = clothlab::xpbd_distance_projection(x_i, x_j, 1.0, 1.0, 1.0, 1.0, lambda);
    {
      // What a wrong answer here usually is, -1/9 (and the pair pulled closer) without the term
      // -alpha_tilde lambda and -1/3 with nothing moved, is worked out in slips.hpp
      // (kXpbdSecondIteration).
      std::ostringstream said;
      said << "iteration 2, lambda = -1/3: C = 1/3 = -alpha_tilde lambda, so delta_lambda = 0 "
              "and the pair stays 4/3 apart: delta_lambda = (-C - alpha_tilde lambda) / (w_i + "
              "w_j + alpha_tilde) (hints 2 and 4); got "
           << dl2 << " and length " << (x_j - x_i).norm();
      INFO(grading::hint(dl2, grading::slips::kXpbdSecondIteration, 1e-9, said.str()));
      CHECK(std::abs(dl2) <= 1e-12);
      CHECK((x_j - x_i).norm() == doctest::Approx(4.0 / 3.0).epsilon(1e-12));
    }
    {
      // The same pair with lambda = -0.5 given: delta_lambda = (-1 + 0.5) / 3 = -1/6; x_i ->
      // (1/6, 0, 0), x_j -> (11/6, 0, 0).
      const Projected p = project(Vec3::Zero(), Vec3(2.0, 0.0, 0.0), 1.0, 1.0, 1.0, 1.0, -0.5);
      INFO(
          "x_i = (0, 0, 0), x_j = (2, 0, 0), l0 = 1, w_i = w_j = 1, alpha_tilde = 1, lambda = "
          "-0.5: delta_lambda = (-C - alpha_tilde lambda) / 3 = -1/6 (return delta_lambda, not "
          "lambda + delta_lambda: hint 4); got "
          << p.dl);
      CHECK(p.dl == doctest::Approx(-1.0 / 6.0).epsilon(1e-12));
      CHECK_NEAR_VEC(p.x_i, Vec3(1.0 / 6.0, 0.0, 0.0), 1e-12);
      CHECK_NEAR_VEC(p.x_j, Vec3(11.0 / 6.0, 0.0, 0.0), 1e-12);
    }
    {
      // alpha_tilde = 1 above makes alpha_tilde lambda and lambda alike. With alpha_tilde = 0.5,
      // lambda = -0.8, w_i = 2, w_j = 0.5: delta_lambda = (-1 + 0.4) / (2.5 + 0.5) = -0.2;
      // x_i += 2 (-0.2) (-1, 0, 0) -> (0.4, 0, 0), x_j -= 0.5 (-0.2) (-1, 0, 0) -> (1.9, 0, 0).
      const Projected p = project(Vec3::Zero(), Vec3(2.0, 0.0, 0.0), 2.0, 0.5, 1.0, 0.5, -0.8);
      INFO(
          "x_i = (0, 0, 0), x_j = (2, 0, 0), l0 = 1, w_i = 2, w_j = 0.5, alpha_tilde = 0.5, "
          "lambda = -0.8: delta_lambda = (-C - alpha_tilde lambda) / (w_i + w_j + alpha_tilde) = "
          "-0.6 / 3 = -0.2; got "
          << p.dl);
      CHECK(p.dl == doctest::Approx(-0.2).epsilon(1e-12));
      CHECK_NEAR_VEC(p.x_i, Vec3(0.4, 0.0, 0.0), 1e-12);
      CHECK_NEAR_VEC(p.x_j, Vec3(1.9, 0.0, 0.0), 1e-12);
    }
  }
}
