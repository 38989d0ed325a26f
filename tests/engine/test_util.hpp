// test_util.hpp: small helpers shared by the engine tests: the worlds and scenes that several
// files build, running a scene, and finding an effect in a world.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/step_timer.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/euler.hpp"
#include "clothlab/integrators/methods.hpp"
#include "scene/scene.hpp"
#include "scene/simulation.hpp"

namespace test {

// ---- Integrators ----------------------------------------------------------------------------

// Every integrator a scene may name, in the engine's order (clothlab::integrator_names()).
inline std::vector<std::string> all_integrators() {
  return {clothlab::integrator_names().begin(), clothlab::integrator_names().end()};
}

// ---- Worlds built in code -------------------------------------------------------------------

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

// Two particles on one spring (ks [N/m], kd [N s/m], l0 = 1 m) along x: the 1D oscillator of
// integrators.cpp, stability.cpp and advisor.cpp. Particle 1 (mass m1 [kg]) starts at
// displacement x0 [m] from rest with velocity v0 [m/s]. With m0 = 0 particle 0 is the pinned
// anchor at the origin; otherwise it is free, of mass m0, and moves so that the pair's momentum
// is zero: then the stretch obeys the oscillator with the reduced mass m0 m1 / (m0 + m1) in
// place of m1. The world has no integrator yet: each file sets its own.
inline clothlab::World spring_pair(double m0, double m1, double ks, double kd, double x0,
                                   double v0) {
  clothlab::World world;
  world.particles.add(clothlab::Vec3::Zero(), clothlab::Vec3::Zero(), m0 > 0.0 ? m0 : 1.0);
  if (m0 > 0.0) {
    const double share = m1 / (m0 + m1);  // the anchor's part of the relative motion
    world.particles.x(0, 0) = -share * x0;
    world.particles.v(0, 0) = -share * v0;
    x0 *= 1.0 - share;
    v0 *= 1.0 - share;
  } else {
    clothlab::pin(world.particles, 0);
  }
  world.particles.add(clothlab::Vec3(1.0 + x0, 0.0, 0.0), clothlab::Vec3(v0, 0.0, 0.0), m1);
  clothlab::SpringSet springs;
  springs.add(0, 1, ks, kd, 1.0);
  world.force_effects.push_back(
      std::make_unique<clothlab::SpringDampers>("springs", std::move(springs)));
  return world;
}

// The oscillator of spring_pair with its anchor pinned: m x'' = -ks x - kd x', x the
// displacement of particle 1 (mass m [kg]) from 1 m. No integrator yet.
inline clothlab::World anchored_spring(double m, double ks, double kd, double x0, double v0) {
  return spring_pair(0.0, m, ks, kd, x0, v0);
}

// ---- Scenes ---------------------------------------------------------------------------------

// A sheet of 12 x 12 particles 5 cm apart, 0.15 kg in all, hanging from its top edge in a
// 30 m/s storm for 1.5 s (tearing.cpp, hard_cases.cpp): with [plasticity] or [tearing] among the
// extra `tables` it stretches, yields and tears. The text ends inside its [integrator] table
// (dt and duration), so a test may append keys to it (the method); where a table stands in the
// text does not matter, the engine reads them in its own order.
inline std::string storm(const std::string& tables = "") {
  return R"(
[cloth]
rows = 12
cols = 12
spacing = 0.05
mass = 0.15
pins = "top-edge"
[springs]
ks = 40
kd = 0.02
[gravity]
[aerodynamics]
wind = [0, 0, 30]
)" + tables +
         R"(
[integrator]
dt = 0.0002
duration = 1.5
)";
}

// Steps `world` `steps` times by dt [s], requiring that no step ends with more energy than it
// began with (beyond rounding, 1e-12 J); returns the energy at the end [J].
inline double step_without_energy_growth(clothlab::World& world, double dt, int steps) {
  double e = world.kinetic_energy() + world.potential_energy();
  for (int s = 0; s < steps; ++s) {
    world.step(dt);
    const double next = world.kinetic_energy() + world.potential_energy();
    REQUIRE(next <= e + 1e-12);
    e = next;
  }
  return e;
}

// Steps `scene` through its whole duration: step_count() steps of its dt.
inline void run_to_end(clothlab::Scene& scene) {
  for (long s = 0; s < scene.step_count(); ++s)
    scene.world.step(scene.dt);
}

// ---- Methods that take whole steps their own way (lessons 12 and 13) -------------------------

// A stiff sheet of 10 x 10 particles 5 cm apart, 1 g each, ks = 5000 N/m, at dt = 1/60 s with
// `method`: dt w ~ 75, far past any explicit method's limit (about 2).
inline std::string stiff_sheet(const std::string& method) {
  return R"(
[cloth]
rows = 10
cols = 10
spacing = 0.05
mass = 0.1
pins = "top-corners"
[springs]
ks = 5000
kd = 0.01
[gravity]
[integrator]
dt = 0.016666666666666666
duration = 2
method = ")" +
         method + "\"\n";
}

// An 8 x 8 cloth falling on a sphere (centre (0, 0.5, 0), radius 0.3) above the ground y = 0, with
// bending springs, for 2 s at dt = 0.01 s; `integrator_keys` go into its [integrator] table.
inline std::string drape(const std::string& integrator_keys) {
  return R"(
[cloth]
rows = 8
cols = 8
spacing = 0.1
origin = [-0.35, 1.0, -0.35]
plane = "horizontal"
mass = 0.2
[springs]
ks = 2000
kd = 0.02
[bending]
ks = 10
[gravity]
[sphere]
centre = [0, 0.5, 0]
radius = 0.3
[ground]
y = 0
e = 0
mu_s = 0.5
mu_d = 0.4
[integrator]
dt = 0.01
duration = 2
)" + integrator_keys;
}

// The scene `text` stepped `steps` times with the fast path and without it, side by side, and
// what the fast path's backend took of the steps (times).
struct FastAndReadable {
  clothlab::Scene fast, readable;
  clothlab::StepTimer timer;  // on the fast path's world, as --stats times it
  clothlab::StepTimes times;  // what it measured
};
inline std::unique_ptr<FastAndReadable> step_fast_and_readable(const std::string& text, int steps) {
  auto both = std::make_unique<FastAndReadable>(
      FastAndReadable{clothlab::parse_scene(text, "fast.toml"),
                      clothlab::parse_scene(text, "readable.toml"),
                      {},
                      {}});
  both->readable.world.backend.reset();
  REQUIRE(both->fast.world.backend != nullptr);
  both->timer.attach(both->fast.world);
  for (int s = 0; s < steps; ++s) {
    both->fast.world.step(both->fast.dt);
    both->readable.world.step(both->readable.dt);
  }
  both->times = both->timer.times;
  return both;
}

// The scene `text` stepped 200 times with and without the fast path: the same state, bit for
// bit, and the fast path took no step and no force sum (it takes whole steps for the Euler
// methods only).
inline void check_fast_path_declines(const std::string& text) {
  const auto both = step_fast_and_readable(text, 200);
  const clothlab::Scene &fast = both->fast, &readable = both->readable;
  CHECK(both->times.backend_steps == 0.0);
  CHECK(fast.world.backend_evaluations == 0);
  const bool same_x = fast.world.particles.x == readable.world.particles.x;
  const bool same_v = fast.world.particles.v == readable.world.particles.v;
  CHECK(same_x);
  CHECK(same_v);
}

// The game loop (lesson 11) on the scene `text`: one frame of 0.1 s and six of 1/60 s both take
// 500 steps of 0.2 ms and end with the same positions, bit for bit.
inline void check_frames_do_not_matter(const std::string& text) {
  clothlab::Simulation one(clothlab::parse_scene(text, "one.toml"), 100000);
  clothlab::Simulation many(clothlab::parse_scene(text, "many.toml"), 100000);
  one.advance(0.1);
  for (int k = 0; k < 6; ++k)
    many.advance(1.0 / 60.0);
  REQUIRE(one.steps() == 500);
  REQUIRE(many.steps() == 500);
  const bool same = one.positions() == many.positions();
  CHECK(same);
}

// ---- Finding effects ------------------------------------------------------------------------

// The spring effect of `world` called `name` ("springs" or "bending"); the test case fails
// (REQUIRE) if there is none.
inline clothlab::SpringDampers& spring_effect(clothlab::World& world,
                                              std::string_view name = "springs") {
  clothlab::SpringDampers* springs = clothlab::find_spring_effect(world, name);
  REQUIRE(springs != nullptr);
  return *springs;
}

inline const clothlab::SpringDampers& spring_effect(const clothlab::World& world,
                                                    std::string_view name = "springs") {
  const clothlab::SpringDampers* springs = clothlab::find_spring_effect(world, name);
  REQUIRE(springs != nullptr);
  return *springs;
}

// The springs of the spring effect `name`, as spring_effect finds it.
inline clothlab::SpringSet& springs_of(clothlab::World& world, std::string_view name = "springs") {
  return spring_effect(world, name).springs();
}

inline const clothlab::SpringSet& springs_of(const clothlab::World& world,
                                             std::string_view name = "springs") {
  return spring_effect(world, name).springs();
}

// Each spring as the pair (smaller, larger) of its end particles: the same set whatever the
// springs' order in the list and whichever end each lists first.
inline std::set<std::pair<clothlab::Index, clothlab::Index>> ends_of(const clothlab::SpringSet& s) {
  std::set<std::pair<clothlab::Index, clothlab::Index>> ends;
  for (size_t k = 0; k < s.size(); ++k)
    ends.insert({std::min(s.i(k), s.j(k)), std::max(s.i(k), s.j(k))});
  return ends;
}

// The first force effect of `world` that is a T (clothlab::Aerodynamics, ...), or nullptr.
template <class T>
const T* find_force_effect(const clothlab::World& world) {
  for (const auto& e : world.force_effects) {
    if (const auto* found = dynamic_cast<const T*>(e.get())) return found;
  }
  return nullptr;
}

// The first post-step effect of `world` that is a T (clothlab::SelfCollision, ...), or nullptr.
template <class T>
T* find_post_step_effect(clothlab::World& world) {
  for (auto& e : world.post_step_effects) {
    if (auto* found = dynamic_cast<T*>(e.get())) return found;
  }
  return nullptr;
}

}  // namespace test
