// test_util.hpp: small helpers shared by the engine tests.
#pragma once

#include <memory>
#include <string>

#include "clothlab/euler.hpp"
#include "clothlab/gravity.hpp"
#include "clothlab/world.hpp"

namespace test {

// One particle of mass m [kg] at rest at x0 under gravity g, with the named integrator.
inline clothlab::World falling_particle(const std::string& method, double m = 1.0,
                                        const clothlab::Vec3& x0 = clothlab::Vec3::Zero(),
                                        double g = 9.8) {
  clothlab::World world;
  world.particles.add(x0, clothlab::Vec3::Zero(), m);
  world.force_effects.push_back(
      std::make_unique<clothlab::UniformGravity>(clothlab::Vec3(0.0, -g, 0.0)));
  world.integrator = clothlab::make_integrator(method);
  return world;
}

}  // namespace test
