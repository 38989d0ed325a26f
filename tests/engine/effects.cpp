// A scene simulates exactly the effects it names, and nothing else.
#include <doctest/doctest.h>

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
