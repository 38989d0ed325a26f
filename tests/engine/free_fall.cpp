// Free fall through the whole engine (scene-free): both Euler methods against 1/2 g t^2.
#include <doctest/doctest.h>

#include <cmath>

#include "test_util.hpp"

using clothlab::Vec3;

TEST_CASE("free fall: symplectic Euler matches the exact drop plus g dt t / 2") {
  // Exact: y(t) = -g t^2 / 2. Symplectic Euler from rest: y_n = -g dt^2 n(n+1)/2
  //   = -g t^2/2 - g dt t/2, so it falls ahead of the parabola by g dt t / 2, exactly.
  const double g = 9.8, dt = 1e-3;
  const int n = 2000;  // t = 2 s
  clothlab::World world = test::falling_particle("symplectic-euler", 0.7, Vec3::Zero(), g);
  for (int k = 0; k < n; ++k)
    world.step(dt);
  const double t = n * dt;
  CHECK(world.t == doctest::Approx(t));
  CHECK(world.particles.x(1, 0) ==
        doctest::Approx(-0.5 * g * t * t - 0.5 * g * dt * t).epsilon(1e-12));
  CHECK(world.particles.v(1, 0) == doctest::Approx(-g * t).epsilon(1e-12));
  CHECK(world.particles.x(0, 0) == 0.0);  // nothing pushes sideways
  CHECK(world.particles.x(2, 0) == 0.0);
}

TEST_CASE("free fall: explicit Euler lags the exact drop by g dt t / 2") {
  // Explicit Euler from rest: y_n = -g dt^2 n(n-1)/2 = -g t^2/2 + g dt t/2.
  const double g = 9.8, dt = 1e-3;
  const int n = 2000;
  clothlab::World world = test::falling_particle("explicit-euler", 3.0, Vec3::Zero(), g);
  for (int k = 0; k < n; ++k)
    world.step(dt);
  const double t = n * dt;
  CHECK(world.particles.x(1, 0) ==
        doctest::Approx(-0.5 * g * t * t + 0.5 * g * dt * t).epsilon(1e-12));
}

TEST_CASE("free fall: both Euler errors are first order in dt") {
  // The error at fixed t = 1 s is g dt t / 2 for both methods: halving dt halves it.
  for (const char* method : {"explicit-euler", "symplectic-euler"}) {
    CAPTURE(method);
    double error[2];
    const double dts[2] = {1e-2, 5e-3};
    for (int i = 0; i < 2; ++i) {
      clothlab::World world = test::falling_particle(method);
      const int n = static_cast<int>(std::lround(1.0 / dts[i]));
      for (int k = 0; k < n; ++k)
        world.step(dts[i]);
      error[i] = std::abs(world.particles.x(1, 0) - (-0.5 * 9.8));
    }
    CHECK(error[0] / error[1] == doctest::Approx(2.0).epsilon(1e-9));
  }
}

TEST_CASE("free fall: the mass does not matter") {
  // a = f / m = m g / m = g for every mass.
  clothlab::World light = test::falling_particle("symplectic-euler", 1e-3);
  clothlab::World heavy = test::falling_particle("symplectic-euler", 1e3);
  for (int k = 0; k < 500; ++k) {
    light.step(0.01);
    heavy.step(0.01);
  }
  CHECK(light.particles.x(1, 0) == doctest::Approx(heavy.particles.x(1, 0)).epsilon(1e-12));
}
