// Collisions with the ground and a sphere (lesson 05): what must hold for any scene.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>

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

// ---- Static friction holds positions, not only velocities -------------------------------------

namespace {

// One particle of 1 kg at `position` under gravity g with the named integrator and contact
// tables; a single test runs it for `duration` [s] at dt [s].
clothlab::Scene resting_particle(const std::string& position, const std::string& g,
                                 const std::string& contact, const std::string& method, double dt,
                                 double duration) {
  return clothlab::parse_scene(
      "[[particle]]\nposition = " + position + "\nmass = 1\n[gravity]\ng = " + g + "\n" + contact +
          "[integrator]\nmethod = \"" + method + "\"\ndt = " + fmt::format("{:.17g}", dt) +
          "\nduration = " + fmt::format("{:.17g}", duration) + "\n",
      "friction.toml");
}

Vec3 position_after(clothlab::Scene& scene) {
  test::run_to_end(scene);
  return scene.world.particles.x.col(0);
}

}  // namespace

TEST_CASE("collision: static friction holds a particle on a floor under tilted gravity") {
  // Gravity tilted to 0.4 g along x: the floor pushes back 9.8 N and friction can hold
  // mu_s 9.8 = 4.9 N >= 3.92 N, so Coulomb's law says it rests. Before contacts held positions it
  // crept 3.9 mm/s at dt = 1 ms (g_t dt each step).
  for (const std::string& method : test::all_integrators()) {
    for (double dt : {1e-3, 1.0 / 60.0}) {
      CAPTURE(method);
      CAPTURE(dt);
      clothlab::Scene scene = resting_particle(
          "[0, 0, 0]", "[3.92, -9.8, 0]", "[ground]\nmu_s = 0.5\nmu_d = 0.4\n", method, dt, 3.0);
      const Vec3 x = position_after(scene);
      CHECK(std::abs(x.x()) <= 1e-12);
      CHECK(std::abs(x.z()) <= 1e-12);
      CHECK(x.y() >= 0.0);
      CHECK(x.y() <= 1e-9);
    }
  }
}

TEST_CASE("collision: past static friction's limit a particle slides with a = g_t - mu_d g_n") {
  // Tilted to 0.6 g > mu_s g: it slides, and dynamic friction takes mu_d g_n: a = 0.2 g, so
  // x = a t^2 / 2 = 8.82 m after 3 s (first-order methods lag it by O(dt)).
  clothlab::Scene scene =
      resting_particle("[0, 0, 0]", "[5.88, -9.8, 0]", "[ground]\nmu_s = 0.5\nmu_d = 0.4\n",
                       "symplectic-euler", 1e-3, 3.0);
  const Vec3 x = position_after(scene);
  CHECK(x.x() == doctest::Approx(0.5 * 0.2 * 9.8 * 9.0).epsilon(0.01));
}

TEST_CASE("collision: static friction holds a particle on a ball 20 degrees from the top") {
  // tan 20 deg = 0.364 <= mu_s = 0.5: it rests, at any dt and with every integrator. Before, it
  // crept 3.4 mm/s at dt = 1 ms, and at a game's 1/60 s slid off within 3 s.
  const double a = 20.0 * std::numbers::pi / 180.0;
  const std::string start = fmt::format("[{:.17g}, {:.17g}, 0]", std::sin(a), std::cos(a));
  for (const std::string& method : test::all_integrators()) {
    for (double dt : {1e-3, 1.0 / 60.0}) {
      CAPTURE(method);
      CAPTURE(dt);
      clothlab::Scene scene = resting_particle(
          start, "[0, -9.8, 0]",
          "[sphere]\ncentre = [0, 0, 0]\nradius = 1\nmu_s = 0.5\nmu_d = 0.4\n", method, dt, 3.0);
      const Vec3 x = position_after(scene);
      CHECK((x - Vec3(std::sin(a), std::cos(a), 0.0)).norm() <= 1e-9);
    }
  }
  // At 35 deg, tan 35 deg = 0.70 > mu_s: it slides off.
  const double b = 35.0 * std::numbers::pi / 180.0;
  clothlab::Scene steep = resting_particle(
      fmt::format("[{:.17g}, {:.17g}, 0]", std::sin(b), std::cos(b)), "[0, -9.8, 0]",
      "[sphere]\ncentre = [0, 0, 0]\nradius = 1\nmu_s = 0.5\nmu_d = 0.4\n", "symplectic-euler",
      1e-3, 0.5);
  CHECK(position_after(steep).x() > std::sin(b) + 0.05);
}

TEST_CASE("collision: a block on a ramp sticks while tan(angle) <= mu_s, else slides") {
  // A [[plane]] through the origin tilted by `angle` about z; the particle starts on it, at rest.
  // Sliding, it accelerates down the slope at g (sin a - mu_d cos a).
  const double mu_s = 0.5, mu_d = 0.3, g = 9.8;
  for (double degrees : {20.0, 26.0, 30.0, 45.0}) {
    CAPTURE(degrees);
    const double a = degrees * std::numbers::pi / 180.0;
    const Vec3 normal(-std::sin(a), std::cos(a), 0.0);  // the slope rises along +x
    const Vec3 start(2.0 * std::cos(a), 2.0 * std::sin(a), 0.0);
    const std::string plane = fmt::format(
        "[[plane]]\npoint = [0, 0, 0]\nnormal = [{:.17g}, {:.17g}, 0]\nmu_s = {}\n"
        "mu_d = {}\n",
        normal.x(), normal.y(), mu_s, mu_d);
    for (const std::string& method :
         {std::string("symplectic-euler"), std::string("implicit-euler")}) {
      CAPTURE(method);
      const double duration = 0.5;
      clothlab::Scene scene =
          resting_particle(fmt::format("[{:.17g}, {:.17g}, 0]", start.x(), start.y()),
                           "[0, -9.8, 0]", plane, method, 1e-3, duration);
      const Vec3 x = position_after(scene);
      const double along = (start - x).dot(Vec3(std::cos(a), std::sin(a), 0.0));  // down the slope
      CHECK((x - start).dot(normal) >= -1e-12);  // never inside the ramp
      if (std::tan(a) <= mu_s) {
        CHECK(std::abs(along) <= 1e-9);
      } else {
        const double expected = 0.5 * g * (std::sin(a) - mu_d * std::cos(a)) * duration * duration;
        CHECK(along == doctest::Approx(expected).epsilon(0.02));
      }
    }
  }
}

TEST_CASE("collision: a plane's normal must have a direction") {
  const std::string text =
      "[[particle]]\nposition = [0, 0, 0]\nmass = 1\n[[plane]]\npoint = [0, 0, 0]\nnormal = [0, 0, "
      "0]\n"
      "[integrator]\ndt = 0.001\nduration = 1\n";
  CHECK_THROWS_WITH(clothlab::parse_scene(text, "ramp.toml"),
                    doctest::Contains("ramp.toml:6:10: normal = [0, 0, 0] has no direction"));
}
