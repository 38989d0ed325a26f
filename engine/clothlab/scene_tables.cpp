#include "clothlab/scene_tables.hpp"

#include <array>
#include <vector>

#include <fmt/format.h>

#include "clothlab/gravitation.hpp"
#include "clothlab/gravity.hpp"

namespace clothlab {

namespace {

// [[particle]]: one point mass (lesson 01).
void read_particle(SceneTable& t, Scene& scene) {
  const Vec3 x = t.required_vec3("position", "m");
  const Vec3 v = t.vec3("velocity", "m/s", Vec3::Zero());
  const double m = t.required_number("mass", Range::positive("kg"));
  scene.world.particles.add(x, v, m);
}

// [gravity]: uniform gravity, f = m g (lesson 01).
void read_gravity(SceneTable& t, Scene& scene) {
  const Vec3 g = t.vec3("g", "m/s^2", Vec3(0.0, -9.8, 0.0));
  scene.world.force_effects.push_back(std::make_unique<UniformGravity>(g));
}

// [gravitation]: Newton's gravitation between every pair of particles (lesson 01).
void read_gravitation(SceneTable& t, Scene& scene) {
  const double G = t.number("G", Range::positive("N m^2/kg^2"), kGravitationalConstant);
  scene.world.force_effects.push_back(std::make_unique<Gravitation>(G));
}

// [integrator]: the method, the time step and how long to simulate.
void read_integrator(SceneTable& t, Scene& scene) {
  const std::vector<std::string_view> names(integrator_names().begin(), integrator_names().end());
  scene.world.integrator = make_integrator(t.choice("method", names, "symplectic-euler"));
  scene.dt = t.required_number("dt", Range::positive("s"));
  scene.duration = t.required_number("duration", Range::positive("s"));
  if (scene.dt > scene.duration) {
    t.fail("dt", fmt::format("dt = {} s is longer than duration = {} s; expected dt <= duration",
                             scene.dt, scene.duration));
  }
}

// [output]: what a run writes.
void read_output(SceneTable& t, Scene& scene) {
  scene.output.fps = t.number("fps", Range::positive("frames/s"), scene.output.fps);
}

// [guard]: the bounds beyond which a run is stopped as blown up.
void read_guard(SceneTable& t, Scene& scene) {
  Guard& guard = scene.world.guard;
  guard.max_position = t.number("max_position", Range::positive("m"), guard.max_position);
  guard.max_speed = t.number("max_speed", Range::positive("m/s"), guard.max_speed);
}

// The order here is the order of reading: whatever creates particles comes first.
constexpr std::array kKinds = {
    SceneTableKind{"particle", true, false, "position velocity mass",
                   "[[particle]] with position, velocity and mass", read_particle},
    SceneTableKind{"gravity", false, false, "g", "[gravity] with g", read_gravity},
    SceneTableKind{"gravitation", false, false, "G", "[gravitation] with G", read_gravitation},
    SceneTableKind{"integrator", false, true, "method dt duration",
                   "[integrator] with method, dt [s] and duration [s]", read_integrator},
    SceneTableKind{"output", false, false, "fps", "[output] with fps", read_output},
    SceneTableKind{"guard", false, false, "max_position max_speed",
                   "[guard] with max_position and max_speed", read_guard},
};

}  // namespace

std::span<const SceneTableKind> scene_table_kinds() {
  return kKinds;
}

const SceneTableKind* find_scene_table(std::string_view name) {
  for (const SceneTableKind& kind : kKinds) {
    if (kind.name == name) return &kind;
  }
  return nullptr;
}

std::string scene_table_names() {
  std::string names = "title";
  for (const SceneTableKind& kind : kKinds)
    names += " " + std::string(kind.name);
  return names;
}

void check_scene(const Scene& scene, const std::function<void(const std::string&)>& fail) {
  if (scene.world.particles.size() == 0) {
    fail("the scene has no particles; expected at least one [[particle]] table");
  }
}

}  // namespace clothlab
