// Collisions with the ground and a sphere (lesson 05): what must hold for any scene.
#include <doctest/doctest.h>

#include <string>

#include "clothlab/after_step/ground_collision.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;
using clothlab::Vec3;

namespace {

clothlab::Scene one_particle(const std::string& position, const std::string& velocity,
                             const std::string& ground, double dt = 0.001, double duration = 1.0) {
  return clothlab::parse_scene("[[particle]]\nposition = " + position + "\nvelocity = " + velocity +
                                   "\nmass = 1\n[gravity]\n[ground]\n" + ground +
                                   "[integrator]\ndt = " + std::to_string(dt) +
                                   "\nduration = " + std::to_string(duration) + "\n",
                               "contact.toml");
}

}  // namespace

TEST_CASE("collision: nothing ends a step below the ground, even at 10^4 m/s") {
  // 10^4 m/s for 1 ms crosses 10 m in one step: the post-step effect still puts it on the plane.
  clothlab::Scene scene = one_particle("[0, 5, 0]", "[3, -10000, 0]", "e = 0.5\n");
  scene.world.guard.max_speed = 1e5;
  for (long s = 0; s < scene.step_count(); ++s) {
    scene.world.step(scene.dt);
    REQUIRE(scene.world.particles.x(1, 0) >= 0.0);
  }
}

TEST_CASE("collision: a particle that starts below the ground is put on it after one step") {
  clothlab::Scene scene = one_particle("[0, -2, 0]", "[0, 0, 0]", "");
  scene.world.step(scene.dt);
  CHECK(scene.world.particles.x(1, 0) == 0.0);
  CHECK(scene.world.particles.x.allFinite());
}

TEST_CASE("collision: an elastic bounce never rises higher than it started") {
  // e = 1 and no friction: over many bounces the peaks stay at or below the 1 m start.
  clothlab::Scene scene =
      one_particle("[0, 1, 0]", "[0, 0, 0]", "e = 1\nmu_s = 0\nmu_d = 0\n", 0.001, 10.0);
  double highest_later = 0.0;
  for (long s = 0; s < scene.step_count(); ++s) {
    scene.world.step(scene.dt);
    if (scene.world.t > 0.5) highest_later = std::max(highest_later, scene.world.particles.x(1, 0));
  }
  CHECK(highest_later <= 1.0);
  CHECK(highest_later > 0.98);  // and it does keep bouncing (e = 1 loses nearly nothing)
}

TEST_CASE("collision: friction never adds energy") {
  // Launched along the floor at 5 m/s, the particle slides: its kinetic energy only falls
  // (it is on the ground, so its potential energy is constant), to zero when it stops.
  clothlab::Scene scene =
      one_particle("[0, 0, 0]", "[5, 0, 2]", "mu_s = 0.5\nmu_d = 0.4\n", 0.001, 3.0);
  double previous = scene.world.kinetic_energy();
  for (long s = 0; s < scene.step_count(); ++s) {
    scene.world.step(scene.dt);
    const double ke = scene.world.kinetic_energy();
    REQUIRE(ke <= previous + 1e-12);
    previous = ke;
  }
  CHECK(previous == 0.0);  // static friction holds it still at the end
}

TEST_CASE("collision: a slide stops after v0^2 / (2 mu_d g)") {
  // Each step gravity gives v.y = -g dt, the bounce (e = 0 below rest_speed) takes it back,
  // with impulse j = g dt: dynamic friction removes mu_d g dt of sliding speed per step, the
  // continuous deceleration mu_d g. v0 = 4 m/s, mu_d = 0.4: d = 16 / (2 * 0.4 * 9.8) = 2.0408 m.
  clothlab::Scene scene =
      one_particle("[0, 0, 0]", "[4, 0, 0]", "mu_s = 0.5\nmu_d = 0.4\n", 0.0005, 2.0);
  test::run_to_end(scene);
  CHECK(scene.world.particles.v.col(0).isZero(0.0));
  CHECK(scene.world.particles.x(0, 0) == doctest::Approx(16.0 / (2 * 0.4 * 9.8)).epsilon(0.005));
}

TEST_CASE("collision: a cloth lying on the ground comes to rest and stays") {
  clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 10
cols = 10
spacing = 0.05
plane = "horizontal"
origin = [0, 0.3, 0]
mass = 0.1
[springs]
ks = 80
kd = 0.05
[gravity]
[ground]
e = 0.3
[integrator]
dt = 0.0005
duration = 4
)",
                                                "floor.toml");
  double peak = 0.0;
  for (long s = 0; s < scene.step_count(); ++s) {
    scene.world.step(scene.dt);
    peak = std::max(peak, scene.world.kinetic_energy());
    REQUIRE(scene.world.particles.x.row(1).minCoeff() >= 0.0);              // never sinks
    if (scene.world.t > 3.0) REQUIRE(scene.world.kinetic_energy() < 1e-9);  // calm at the end
  }
  CHECK(peak > 0.01);  // it did fall: 0.1 kg from 0.3 m is 0.29 J
  // No creep: the cloth is lying where it landed, its corner not slid away.
  CHECK(std::abs(scene.world.particles.x(0, 0)) < 1e-6);
}

TEST_CASE("collision: no particle ends a step inside the sphere") {
  clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 12
cols = 12
spacing = 0.05
plane = "horizontal"
origin = [-0.275, 0.5, -0.275]
mass = 0.1
[springs]
ks = 80
kd = 0.05
[gravity]
[sphere]
centre = [0, 0, 0]
radius = 0.3
[integrator]
dt = 0.0005
duration = 2
)",
                                                "drape.toml");
  for (long s = 0; s < scene.step_count(); ++s) {
    scene.world.step(scene.dt);
    REQUIRE(scene.world.particles.x.colwise().norm().minCoeff() >= 0.3 - 1e-12);
  }
  // The middle of the cloth rests on top of the ball, at its radius.
  CHECK(scene.world.particles.x.colwise().norm().minCoeff() == doctest::Approx(0.3));
}
