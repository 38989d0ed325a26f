// A scene simulates exactly the effects it names, and nothing else.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "clothlab/forces/gravity.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

namespace {

std::string effect_names(const clothlab::World& world) {
  std::string names;
  for (const auto& e : world.force_effects)
    names += std::string(e->name()) + ";";
  for (const auto& e : world.post_step_effects)
    names += std::string(e->name()) + ";";
  return names;
}

const char* kOneParticle = R"(
[[particle]]
position = [0, 0, 0]
velocity = [1, 2, 3]
mass = 2
[integrator]
dt = 0.01
duration = 1
)";

}  // namespace

TEST_CASE("effects: a scene with no effect tables constructs no effect") {
  clothlab::Scene scene = clothlab::parse_scene(kOneParticle, "none.toml");
  CHECK(scene.world.force_effects.empty());
  CHECK(scene.world.post_step_effects.empty());
  // Nothing acts on the particle, so it keeps its velocity: Newton's first law.
  test::run_to_end(scene);
  CHECK(scene.world.particles.v.col(0).isApprox(clothlab::Vec3(1, 2, 3)));
  CHECK(scene.world.particles.x.col(0).isApprox(clothlab::Vec3(1, 2, 3)));
}

TEST_CASE("effects: naming [gravity] constructs gravity and nothing else") {
  clothlab::Scene scene =
      clothlab::parse_scene(std::string(kOneParticle) + "[gravity]\n", "gravity.toml");
  CHECK(effect_names(scene.world) == "gravity;");
  const auto* gravity =
      dynamic_cast<const clothlab::UniformGravity*>(scene.world.force_effects[0].get());
  REQUIRE(gravity != nullptr);
  CHECK(gravity->g().isApprox(clothlab::Vec3(0, -9.8, 0)));  // the lecture's default
}

TEST_CASE("effects: naming [gravitation] constructs gravitation and nothing else") {
  clothlab::Scene scene =
      clothlab::parse_scene(std::string(kOneParticle) + "[gravitation]\nG = 1.0\n", "g.toml");
  CHECK(effect_names(scene.world) == "gravitation;");
}

TEST_CASE("effects: the integrator is the one the scene names") {
  clothlab::Scene by_default = clothlab::parse_scene(kOneParticle, "a.toml");
  CHECK(by_default.world.integrator->name() == "symplectic-euler");
  std::string text = kOneParticle;
  text.replace(text.find("dt = 0.01"), 9, "dt = 0.01\nmethod = \"explicit-euler\"");
  clothlab::Scene named = clothlab::parse_scene(text, "b.toml");
  CHECK(named.world.integrator->name() == "explicit-euler");
}

TEST_CASE("effects: the step count covers the duration") {
  clothlab::Scene scene = clothlab::parse_scene(kOneParticle, "a.toml");
  CHECK(scene.step_count() == 100);  // 1 s / 0.01 s
}

TEST_CASE("buoyancy: an undamped float keeps its total energy as it rises and bobs") {
  // 0.5 kg displacing 1 litre of water starts 1 m under: the fluid lifts 9.8 N against 4.9 N of
  // weight, so it rises, overshoots the surface and falls back. Nothing takes energy out, so
  // kinetic + potential stays what it was, to the integrator's O(dt) error at the surface
  // crossings. (With buoyancy's energy of the wrong sign it rose by 2 rho V g depth = 19.6 J.)
  clothlab::Scene scene = clothlab::parse_scene(
      "[[particle]]\nposition = [0, -1, 0]\nmass = 0.5\n[gravity]\n[buoyancy]\nvolume = 1e-3\n"
      "[integrator]\nmethod = \"symplectic-euler\"\ndt = 1e-4\nduration = 4\n",
      "float.toml");
  clothlab::World& world = scene.world;
  const double e0 = world.kinetic_energy() + world.potential_energy();
  double farthest = 0.0, highest = -1.0;
  for (long s = 0; s < scene.step_count(); ++s) {
    world.step(scene.dt);
    farthest = std::max(farthest, std::abs(world.kinetic_energy() + world.potential_energy() - e0));
    highest = std::max(highest, world.particles.x(1, 0));
  }
  CHECK(highest > 0.5);           // it did leave the water: the check covers both sides
  CHECK(farthest <= 1e-3 * 9.8);  // against the 9.8 J the fluid gives it on the way up
}

TEST_CASE("buoyancy: the fluid lifts against gravity's direction, whatever it is") {
  // Gravity along +x: "up" is -x, and the surface is the plane at height 0 along it, x = 0.
  // A particle at x = 1 is 1 m under: the fluid pushes it along -x with rho V |g| = 4.9 N.
  clothlab::Scene scene = clothlab::parse_scene(
      "[[particle]]\nposition = [1, 0, 0]\nmass = 0.5\n[[particle]]\nposition = [-1, 0, 0]\n"
      "mass = 0.5\n[gravity]\ng = [4.9, 0, 0]\n[buoyancy]\nvolume = 1e-3\n"
      "[integrator]\ndt = 1e-3\nduration = 1\n",
      "sideways.toml");
  const clothlab::World& world = scene.world;
  const auto& buoyancy = *world.force_effects.back();
  REQUIRE(buoyancy.name() == "buoyancy");
  clothlab::Matrix3X f = clothlab::Matrix3X::Zero(3, 2);
  buoyancy.add_forces(world.particles, world.particles.x, world.particles.v, f);
  CHECK(f(0, 0) == doctest::Approx(-1000.0 * 1e-3 * 4.9));
  CHECK(f.col(0).tail<2>().norm() == 0.0);
  CHECK(f.col(1).norm() == 0.0);  // above the surface: nothing
  // Its energy: rho V |g| times the depth, 4.9 J for the one 1 m under.
  CHECK(buoyancy.potential_energy(world.particles, world.particles.x) == doctest::Approx(4.9));
}
