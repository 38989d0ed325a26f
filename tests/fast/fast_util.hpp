// fast_util.hpp: what the fast engine's tests share (fast_path.cpp, float.cpp, stencil.cpp): a
// hanging cloth, a scene run on either path, bit-for-bit comparison, the world's fast engine.
#pragma once

#include <doctest/doctest.h>

#include <functional>
#include <string>

#include "clothlab/core/types.hpp"
#include "fast/engine.hpp"
#include "scene/scene.hpp"

namespace test {

// A cloth of rows x cols particles 2 cm apart, 0.5 kg in all, hanging from its top corners, with
// structural, shear and bending springs, damping and gravity: the tables up to [gravity], to
// which a test adds the others (effects, [integrator], [engine]).
inline std::string hanging_cloth(clothlab::Index rows, clothlab::Index cols) {
  return "[cloth]\nrows = " + std::to_string(rows) + "\ncols = " + std::to_string(cols) + R"(
spacing = 0.02
mass = 0.5
pins = "top-corners"
[springs]
ks = 60
kd = 0.02
shear_ks = 40
shear_kd = 0.01
[bending]
ks = 5
kd = 0.002
[damping]
rate = 0.05
[gravity]
)";
}

// The scene stepped `steps` times with the given engine settings, after `edit` (if given) has
// changed its world.
inline clothlab::Scene run(const std::string& text, bool fast, int threads, int steps,
                           const std::function<void(clothlab::World&)>& edit = {}) {
  clothlab::Scene scene = clothlab::parse_scene(text, "fast-path.toml");
  if (edit) edit(scene.world);
  if (!fast) scene.world.backend.reset();
  scene.world.threads = threads;
  for (int s = 0; s < steps; ++s)
    scene.world.step(scene.dt);
  return scene;
}

// Bit for bit: == on doubles (no tolerance).
inline bool identical(const clothlab::Matrix3X& a, const clothlab::Matrix3X& b) {
  return a.cols() == b.cols() && (a.array() == b.array()).all();
}

// The threads' wakes the guard's energy checks add to `steps` steps that start after step
// `start`: one per check for each force effect whose energy the engine room computes on the
// threads (each spring set it takes). Counted on one thread, so that counting wakes nobody.
inline long energy_check_wakes(clothlab::World& world, long start, long steps) {
  const int threads = world.threads;
  world.threads = 1;
  long taken = 0;
  for (const auto& effect : world.force_effects) {
    double energy = 0.0;
    taken += world.backend->potential_energy(world, *effect, world.particles.x, energy);
  }
  world.threads = threads;
  const long every = world.guard.energy_check_every;
  const long checks = (start + steps) / every - start / every;
  REQUIRE(checks >= 1);  // the steps reach a check: the count is tested
  REQUIRE(taken >= 1);
  return checks * taken;
}

// The world's fast engine (a scene installs one unless it says fast_path = false).
inline clothlab::fast::FastEngine& engine_of(const clothlab::World& world) {
  auto* engine = dynamic_cast<clothlab::fast::FastEngine*>(world.backend.get());
  REQUIRE(engine != nullptr);
  return *engine;
}

}  // namespace test
