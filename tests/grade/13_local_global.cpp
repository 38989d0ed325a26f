// Grading tests for lesson 13, a local/global solver (exercise ex13.1, the local step's projection
// of one spring).
//
// Every expected value is worked out in the comment beside it, from the lesson's equation;
// none comes from the reference solution. With e = x_i - x_j and l = |e|:
//   d = l0 e / l,   and d = d_previous when l = 0.
// The numbers are chosen so that every value comes out as a short decimal: e = (0, -3, -4) has
// l = 5 and e / l = (0, -0.6, -0.8).
#include <cmath>
#include <string>

#include "clothlab/integrators/local_global.hpp"
#include "grading.hpp"

using clothlab::Vec3;

namespace {

Vec3 project(const Vec3& x_i, const Vec3& x_j, double l0, const Vec3& d_previous = Vec3::Zero()) {
  return clothlab::local_step_projection(x_i, x_j, l0, d_previous);
}

}  // namespace

TEST_SUITE("ex13") {
  TEST_CASE("ex13.1 a spring at its rest length gives back x_i - x_j" * POINTS(1)) {
    // x_i - x_j = (0, -3, -4): l = 5 = l0, so d = 5 (0, -0.6, -0.8) = (0, -3, -4), e itself.
    const Vec3 d = project(Vec3(1.0, 2.0, 3.0), Vec3(1.0, 5.0, 7.0), 5.0);
    INFO(
        "x_i = (1, 2, 3), x_j = (1, 5, 7), l0 = 5: the spring is at its rest length, so the "
        "nearest vector of length l0 to x_i - x_j is x_i - x_j = (0, -3, -4); got "
        << grading::show(d));
    CHECK_NEAR_VEC(d, Vec3(0.0, -3.0, -4.0), 1e-12);
  }

  TEST_CASE("ex13.1 a spring along an axis stretched and squeezed worked by hand" * POINTS(2)) {
    {
      // x_i = (2, 0, 0), x_j = 0: e = (2, 0, 0), l = 2; l0 = 1: d = 1 (1, 0, 0) = (1, 0, 0).
      const Vec3 d = project(Vec3(2.0, 0.0, 0.0), Vec3::Zero(), 1.0);
      INFO(
          "x_i = (2, 0, 0), x_j = (0, 0, 0), l0 = 1: a spring stretched to twice its length; "
          "d = l0 (x_i - x_j) / l = (1, 0, 0); got "
          << grading::show(d));
      CHECK_NEAR_VEC(d, Vec3(1.0, 0.0, 0.0), 1e-12);
    }
    {
      // x_i = (0, 0.5, 0), x_j = (0, 1, 0): e = (0, -0.5, 0), l = 0.5; l0 = 2: d = (0, -2, 0).
      const Vec3 d = project(Vec3(0.0, 0.5, 0.0), Vec3(0.0, 1.0, 0.0), 2.0);
      INFO(
          "x_i = (0, 0.5, 0), x_j = (0, 1, 0), l0 = 2: a spring squeezed to a quarter of its "
          "length; d = 2 (0, -1, 0) = (0, -2, 0), pointing from x_j to x_i (hint 2); got "
          << grading::show(d));
      CHECK_NEAR_VEC(d, Vec3(0.0, -2.0, 0.0), 1e-12);
    }
  }

  TEST_CASE("ex13.1 a diagonal spring worked by hand" * POINTS(2)) {
    // x_i = (1, 2, 3), x_j = (1, 5, 7): e = (0, -3, -4), l = 5, e / l = (0, -0.6, -0.8).
    //   l0 = 2  (stretched):  d = (0, -1.2, -1.6)
    //   l0 = 10 (squeezed):   d = (0, -6, -8)
    const Vec3 x_i(1.0, 2.0, 3.0), x_j(1.0, 5.0, 7.0);
    const Vec3 stretched = project(x_i, x_j, 2.0), squeezed = project(x_i, x_j, 10.0);
    // What the usual slips give for l0 = 2 is worked out in slips.hpp (kLocalDiagonal).
    INFO(grading::hint(stretched, grading::slips::kLocalDiagonal, 1e-12,
                       "x_i = (1, 2, 3), x_j = (1, 5, 7): x_i - x_j = (0, -3, -4) of length 5; "
                       "l0 = 2 must give (0, -1.2, -1.6) and l0 = 10 must give (0, -6, -8); got " +
                           grading::show(stretched) + " and " + grading::show(squeezed)));
    CHECK_NEAR_VEC(stretched, Vec3(0.0, -1.2, -1.6), 1e-12);
    CHECK_NEAR_VEC(squeezed, Vec3(0.0, -6.0, -8.0), 1e-12);
  }

  TEST_CASE("ex13.1 d has the length l0 and the direction of x_i - x_j" * POINTS(1)) {
    // Whatever the pair: |d| = l0 (hint 3), d is parallel to e (d x e = 0) and points the same
    // way (d . e > 0); swapping the ends turns d around.
    const Vec3 pairs[][2] = {{Vec3(0.3, -1.7, 2.2), Vec3(-0.4, 0.9, 1.1)},
                             {Vec3(5.0, 5.0, 5.0), Vec3(5.001, 4.998, 5.0)},
                             {Vec3(-2.0, 0.0, 1.0), Vec3(3.0, 7.0, -6.0)}};
    for (const auto& pair : pairs) {
      const double l0 = 0.75;
      const Vec3 e = pair[0] - pair[1];
      const Vec3 d = project(pair[0], pair[1], l0), swapped = project(pair[1], pair[0], l0);
      INFO("x_i = " << grading::show(pair[0]) << ", x_j = " << grading::show(pair[1])
                    << ", l0 = 0.75: got d = " << grading::show(d) << " of length " << d.norm()
                    << ", and with the ends swapped " << grading::show(swapped));
      CHECK(d.norm() == doctest::Approx(l0).epsilon(1e-12));
      CHECK(d.cross(e).norm() <= 1e-12 * e.norm());
      CHECK(d.dot(e) > 0.0);
      CHECK_NEAR_VEC(swapped, -d, 1e-12);
    }
  }

  TEST_CASE("ex13.1 coincident ends keep the previous d and never give NaN" * POINTS(1)) {
    // x_i = x_j: l = 0 and e / l = 0 / 0. Every d of length l0 is as near as any other: the
    // local step keeps the spring's last d (hint 1), exactly as given.
    const Vec3 x(0.5, -1.0, 2.0), previous(0.0, 0.0, -1.5);
    const Vec3 d = project(x, x, 1.5, previous);
    INFO(
        "x_i = x_j = (0.5, -1, 2), l0 = 1.5, d_previous = (0, 0, -1.5): no direction to take, "
        "so d = d_previous; got "
        << grading::show(d));
    CHECK(std::isfinite(d.x()));
    CHECK(std::isfinite(d.y()));
    CHECK(std::isfinite(d.z()));
    CHECK(d == previous);
    // Only l == 0 is special: 1 mm apart along e / l = (0.6, 0, 0.8) the ends give their own
    // direction, d = 1.5 (0.6, 0, 0.8) = (0.9, 0, 1.2), whatever d_previous was.
    const Vec3 near = project(x + 0.001 * Vec3(0.6, 0.0, 0.8), x, 1.5, previous);
    INFO("ends 1 mm apart have a direction: d = 1.5 (0.6, 0, 0.8) = (0.9, 0, 1.2); got "
         << grading::show(near));
    CHECK_NEAR_VEC(near, Vec3(0.9, 0.0, 1.2), 1e-10);
  }

  TEST_CASE("ex13.1 d depends on x_i - x_j and l0 alone" * POINTS(1)) {
    // The diagonal spring of the cases above, moved by (10, -20, 30): e is the same, so d is
    // (0, -1.2, -1.6) again. And with the ends apart, d_previous plays no part.
    const Vec3 shift(10.0, -20.0, 30.0);
    const Vec3 d =
        project(Vec3(1.0, 2.0, 3.0) + shift, Vec3(1.0, 5.0, 7.0) + shift, 2.0, Vec3(7.0, 7.0, 7.0));
    INFO(
        "the pair x_i = (1, 2, 3), x_j = (1, 5, 7) moved by (10, -20, 30), l0 = 2, with "
        "d_previous = (7, 7, 7): d must still be (0, -1.2, -1.6), the ends being apart; got "
        << grading::show(d));
    CHECK_NEAR_VEC(d, Vec3(0.0, -1.2, -1.6), 1e-12);
  }
}
