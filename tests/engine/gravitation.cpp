// Two bodies under Newton's gravitation: what must hold whatever the step size.
#include <doctest/doctest.h>

#include <cmath>

#include "clothlab/core/world.hpp"
#include "clothlab/forces/gravitation.hpp"
#include "clothlab/integrators/methods.hpp"

using clothlab::Vec3;

namespace {

// Two bodies 10 m apart (3e9 kg and 1e9 kg) on a mildly elliptic orbit. With G M = 0.2669
// m^3/s^2 the circular relative speed is sqrt(G M / r) = 0.163 m/s; we give 0.15 m/s, split so
// that the centre of mass would be at rest, then let the whole pair drift at (0.01, 0, 0.005).
clothlab::World binary(const std::string& method) {
  clothlab::World world;
  const Vec3 drift(0.01, 0.0, 0.005);
  world.particles.add(Vec3(-2.5, 0.0, 0.0), Vec3(0.0, -0.0375, 0.0) + drift, 3.0e9);
  world.particles.add(Vec3(7.5, 0.0, 0.0), Vec3(0.0, 0.1125, 0.0) + drift, 1.0e9);
  world.force_effects.push_back(
      std::make_unique<clothlab::Gravitation>(clothlab::kGravitationalConstant));
  world.integrator = clothlab::make_integrator(method);
  return world;
}

}  // namespace

TEST_CASE("gravitation: two bodies keep their total momentum") {
  // The pair forces are equal and opposite, so sum m v changes only by rounding, for either
  // Euler method, however inaccurate the orbit itself is.
  for (const char* method : {"explicit-euler", "symplectic-euler"}) {
    CAPTURE(method);
    clothlab::World world = binary(method);
    const Vec3 p0 = world.momentum();
    const double scale = 3.0e9 * 0.0375;  // a typical momentum [kg m/s], for a relative tolerance
    for (int k = 0; k < 20000; ++k)
      world.step(0.05);
    CHECK((world.momentum() - p0).norm() / scale < 1e-10);
  }
}

TEST_CASE("gravitation: symplectic Euler keeps the orbit's energy bounded") {
  // A bound orbit should neither spiral out nor in. Over several orbits the total energy of a
  // symplectic Euler run wobbles but stays near its start (within 2 % here).
  clothlab::World world = binary("symplectic-euler");
  const double e0 = world.kinetic_energy() + world.potential_energy();
  REQUIRE(e0 < 0.0);  // bound
  double worst = 0.0;
  for (int k = 0; k < 40000; ++k) {
    world.step(0.05);
    const double e = world.kinetic_energy() + world.potential_energy();
    worst = std::max(worst, std::abs(e / e0 - 1.0));
  }
  CHECK(worst < 0.02);
}

TEST_CASE("gravitation: the potential energy is -G m1 m2 / r") {
  clothlab::World world = binary("symplectic-euler");
  CHECK(world.potential_energy() ==
        doctest::Approx(-clothlab::kGravitationalConstant * 3.0e9 * 1.0e9 / 10.0));
}
