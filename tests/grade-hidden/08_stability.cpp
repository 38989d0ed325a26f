// Hidden grading tests for exercise ex08.1, explicit Euler's largest stable step on a
// spring-damper.
//
// This folder is the instructor's: the student release leaves it out, and the build compiles it
// into the grading binaries only when it is there. Like the visible tests, every expectation is
// derived beside its check and holds for any correct answer.
#include <cmath>

#include "clothlab/integrators/stability_limit.hpp"
#include "grading.hpp"

using clothlab::largest_stable_dt_explicit_euler;

TEST_SUITE("ex08") {
  TEST_CASE("ex08.1 hidden: the limit follows the spring's own time" * POINTS(2)) {
    // m x'' = -k x - c x' divided by s is the same equation: (k, m, c) and (s k, s m, s c) have
    // the same limit. With time stretched by s (k -> k / s^2, c -> c / s, m fixed) every root
    // lambda shrinks by s, so the limit dt = -2 / lambda or c / k grows by s.
    const double cases[][3] = {{100.0, 1.0, 2.0}, {3.0, 1.0, 4.0}, {50.0, 0.5, 12.0}};
    for (const auto& [k, m, c] : cases) {
      const double dt = largest_stable_dt_explicit_euler(k, m, c);
      const double heavier = largest_stable_dt_explicit_euler(7.0 * k, 7.0 * m, 7.0 * c);
      const double slower = largest_stable_dt_explicit_euler(k / 9.0, m, c / 3.0);
      INFO("k = " << k << " N/m, m = " << m << " kg, c = " << c << " N s/m gives " << dt
                  << " s; all of k, m and c times 7 must give the same, got " << heavier
                  << " s; k / 9 and c / 3 (time 3 times slower) must give 3 times as much, got "
                  << slower << " s");
      CHECK(dt > 0.0);
      CHECK(std::abs(heavier - dt) <= 1e-12 * dt);
      CHECK(std::abs(slower - 3.0 * dt) <= 1e-12 * dt);
    }
    // The last of them by hand: 0.5 lambda^2 + 12 lambda + 50 = 0 has the roots
    // lambda = -12 +- sqrt(144 - 100) (overdamped); the faster one, -(12 + sqrt(44)) 1/s,
    // reaches R = -1 at dt = 2 / (12 + sqrt(44)) = 0.10734 s.
    const double overdamped = largest_stable_dt_explicit_euler(50.0, 0.5, 12.0);
    INFO("k = 50 N/m, m = 0.5 kg, c = 12 N s/m: expected 2 / (12 + sqrt(44)) = 0.10734 s, got "
         << overdamped << " s");
    CHECK(std::abs(overdamped - 2.0 / (12.0 + std::sqrt(44.0))) <= 1e-12);
  }

  TEST_CASE("ex08.1 hidden: no jump at critical damping" * POINTS_VISIBILITY(1, hidden)) {
    // k = 25 N/m, m = 1 kg: critical at c = 2 sqrt(k m) = 10 N s/m, where both branches give
    // 2 / w = 0.4 s. A hair below (underdamped, c / k) and a hair above (overdamped,
    // 4 m / (c + sqrt(c^2 - 4 k m)), whose square root grows like sqrt(2e-9) * 10 = 4.5e-4)
    // both lie within 1e-3 of it.
    const double below = largest_stable_dt_explicit_euler(25.0, 1.0, 10.0 * (1.0 - 1e-9));
    const double above = largest_stable_dt_explicit_euler(25.0, 1.0, 10.0 * (1.0 + 1e-9));
    INFO(
        "just below and just above critical damping the limit must be close to 2 / w = 0.4 s; "
        "got "
        << below << " s and " << above << " s");
    CHECK(std::abs(below - 0.4) <= 1e-3);
    CHECK(std::abs(above - 0.4) <= 1e-3);
  }
}
