// Grading tests for lesson 08, stability (exercise ex08.1, explicit Euler's largest stable step on
// a spring-damper).
//
// The test problem is m x'' = -k x - c x'. Its solutions e^(lambda t) have
// m lambda^2 + c lambda + k = 0, and one explicit Euler step multiplies each by
// R = 1 + dt lambda. Every expected value is worked out beside its check from |R| <= 1; the
// last case checks the answer against the step's own matrix, so it holds for any correct
// answer. Limits are compared to 1e-12 relative, never bit for bit.
#include <cmath>
#include <limits>
#include <sstream>

#include "clothlab/integrators/stability_limit.hpp"
#include "grading.hpp"

using clothlab::largest_stable_dt_explicit_euler;

namespace {

bool close(double got, double expected) {
  return std::abs(got - expected) <= 1e-12 * std::abs(expected);
}

// The spectral radius of one explicit Euler step on the spring-damper: (x, v) goes to
// (x + dt v, v + dt (-k x - c v) / m), the matrix [[1, dt], [-dt k/m, 1 - dt c/m]]. Its
// eigenvalues are tr/2 +- sqrt(tr^2/4 - det): complex with modulus sqrt(det), or real.
double explicit_euler_radius(double k, double m, double c, double dt) {
  const double trace = 2.0 - dt * c / m;
  const double det = 1.0 - dt * c / m + dt * dt * k / m;
  const double disc = 0.25 * trace * trace - det;
  if (disc < 0.0) return std::sqrt(det);
  return std::max(std::abs(0.5 * trace + std::sqrt(disc)), std::abs(0.5 * trace - std::sqrt(disc)));
}

}  // namespace

TEST_SUITE("ex08") {
  TEST_CASE("ex08.1 an underdamped spring is stable up to dt = c / k" * POINTS(2)) {
    // k = 400 N/m, m = 0.25 kg, c = 1 N s/m: c^2 = 1 < 4 k m = 400, complex roots, and
    // |R|^2 = 1 - dt c/m + dt^2 k/m <= 1 up to dt = c / k = 0.0025 s; the mass cancels out of the
    // underdamped limit. (Checked first: with m != 1 the usual slips give values of their own.)
    {
      const double b = largest_stable_dt_explicit_euler(400.0, 0.25, 1.0);
      std::ostringstream said;
      said << "k = 400 N/m, m = 0.25 kg, c = 1 N s/m: expected c / k = 0.0025 s, got " << b
           << " s (the mass cancels out of 1 - dt c/m + dt^2 k/m <= 1)";
      // What the usual slips give here is worked out in slips.hpp (kUnderdampedLimit).
      INFO(grading::hint(b, grading::slips::kUnderdampedLimit, 1e-12, said.str()));
      CHECK(close(b, 0.0025));
    }
    // k = 100 N/m, m = 1 kg, c = 2 N s/m (damping ratio 0.1): c / k = 0.02 s.
    const double a = largest_stable_dt_explicit_euler(100.0, 1.0, 2.0);
    INFO("k = 100 N/m, m = 1 kg, c = 2 N s/m (damping ratio 0.1): expected c / k = 0.02 s, got "
         << a << " s. Below critical damping |1 + dt lambda|^2 = 1 - dt c/m + dt^2 k/m");
    CHECK(close(a, 0.02));
  }

  TEST_CASE("ex08.1 a spring without a damper is unstable at every dt" * POINTS(1)) {
    // c = 0: lambda = +-i w, |R|^2 = 1 + dt^2 w^2 > 1 for every dt > 0. The limit is 0.
    const double a = largest_stable_dt_explicit_euler(100.0, 1.0, 0.0);
    INFO(
        "k = 100 N/m, m = 1 kg, no damper: |1 + i dt w|^2 = 1 + (dt w)^2 > 1 at every dt, so "
        "the answer is 0 (unstable at every dt); got "
        << a << " s");
    CHECK(a == 0.0);
    // The smallest damper opens a window: k = 100 N/m, m = 0.3 kg, c = 0.5 N s/m, c^2 = 0.25
    // < 4 k m = 120 (underdamped), stable up to c / k = 0.005 s.
    const double b = largest_stable_dt_explicit_euler(100.0, 0.3, 0.5);
    INFO(
        "k = 100 N/m, m = 0.3 kg and a small damper c = 0.5 N s/m: stable up to c / k = "
        "0.005 s; got "
        << b << " s");
    CHECK(close(b, 0.005));
  }

  TEST_CASE("ex08.1 an overdamped spring is limited by its faster root" * POINTS(2)) {
    // k = 3 N/m, m = 1 kg, c = 4 N s/m: lambda^2 + 4 lambda + 3 = 0, lambda = -1 and -3. The
    // faster root reaches R = 1 - 3 dt = -1 at dt = 2/3 s (c / k = 4/3 s would be twice that).
    const double a = largest_stable_dt_explicit_euler(3.0, 1.0, 4.0);
    INFO(
        "k = 3 N/m, m = 1 kg, c = 4 N s/m (overdamped): the roots are -1 and -3 1/s; 1 - 3 dt "
        ">= -1 gives 2/3 s, got "
        << a << " s. c / k = 4/3 s holds only up to critical damping (c^2 < 4 k m)");
    CHECK(close(a, 2.0 / 3.0));
    // The same roots with m = 2 kg: 2 lambda^2 + 8 lambda + 6 = 0. Still 2/3 s.
    const double b = largest_stable_dt_explicit_euler(6.0, 2.0, 8.0);
    INFO(
        "k = 6 N/m, m = 2 kg, c = 8 N s/m: 2 lambda^2 + 8 lambda + 6 = 0 has the roots -1 and "
        "-3 1/s again, so 2/3 s; got "
        << b << " s");
    CHECK(close(b, 2.0 / 3.0));
  }

  TEST_CASE("ex08.1 at critical damping both formulas give 2 / w" * POINTS(1)) {
    // k = 4 N/m, m = 1 kg, c = 4 N s/m: c^2 = 4 k m, a double root lambda = -2 = -w, and
    // 1 - 2 dt >= -1 up to dt = 1 s = 2 / w = c / k.
    const double a = largest_stable_dt_explicit_euler(4.0, 1.0, 4.0);
    INFO("k = 4 N/m, m = 1 kg, c = 4 N s/m (critical): the double root -2 1/s gives 1 s; got "
         << a << " s");
    CHECK(close(a, 1.0));
  }

  TEST_CASE("ex08.1 a damper alone and a free particle" * POINTS(1)) {
    // k = 0, m = 2 kg, c = 4 N s/m: v' = -(c/m) v, R = 1 - 2 dt >= -1 up to dt = 1 s (the
    // position's root, lambda = 0, has R = 1 and never grows).
    const double a = largest_stable_dt_explicit_euler(0.0, 2.0, 4.0);
    INFO("no spring, m = 2 kg, c = 4 N s/m: v' = -2 v, and 1 - 2 dt >= -1 gives 1 s; got " << a
                                                                                           << " s");
    CHECK(close(a, 1.0));
    // No spring and no damper: nothing grows at any dt.
    const double b = largest_stable_dt_explicit_euler(0.0, 1.0, 0.0);
    INFO("no spring and no damper: every dt is stable, expected infinity; got " << b);
    CHECK(b == std::numeric_limits<double>::infinity());
  }

  TEST_CASE("ex08.1 just below the answer one step shrinks and just above it grows" * POINTS(3)) {
    // Whatever formula gives it, the answer is where the spectral radius of the step's matrix
    // crosses 1: at most 1 at 0.999 of it, above 1 at 1.001 of it. Springs from a cloth's
    // (k = 2e4 N/m on 3.4e-4 kg, damping ratio 0.004) to an overdamped dashpot (ratio 5).
    const double cases[][3] = {{2e4, 3.4e-4, 0.02},
                               {50.0, 0.5, 0.5},
                               {50.0, 0.5, 4.9},
                               {50.0, 0.5, 10.0},
                               {1.0, 1.0, 10.0}};
    for (const auto& [k, m, c] : cases) {
      const double dt = largest_stable_dt_explicit_euler(k, m, c);
      const double below = explicit_euler_radius(k, m, c, 0.999 * dt);
      const double above = explicit_euler_radius(k, m, c, 1.001 * dt);
      INFO("k = " << k << " N/m, m = " << m << " kg, c = " << c << " N s/m: your limit " << dt
                  << " s; the step's spectral radius is " << below << " at 0.999 of it and "
                  << above << " at 1.001 of it (expected <= 1, then > 1)");
      CHECK(std::isfinite(dt));
      CHECK(below <= 1.0 + 1e-12);
      CHECK(above > 1.0);
    }
  }
}
