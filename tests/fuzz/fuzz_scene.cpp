// fuzz_scene.cpp: libFuzzer feeds arbitrary bytes to the scene reader and steps what it accepts.
//
// The contract under test: any input either is rejected with a SceneError, or loads into a world
// that every integrator can step, where a blow-up is reported as a SimulationError by the guard.
// Anything else is a bug: a crash, a sanitizer report, another exception, or a state that went
// non-finite without the guard noticing (checked here with abort()).
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "clothlab/core/guard.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/methods.hpp"
#include "scene/scene.hpp"

namespace {

// Fuzzing needs many inputs a second, so a scene the reader accepts but that would take long to
// step is only read, not stepped: one of more than kMaxParticles particles (a 31 x 31 cloth, the
// size of the lessons' largest), or of more than kMaxParticlesGravitation under [gravitation],
// whose cost grows as n^2. Each integrator takes at most kMaxSteps steps, which runs every effect
// the scene names and blows up a dt that is far too large, and the implicit method's linear
// solver stops after kMaxSolverIterations (its convergence is not what is tested here).
constexpr clothlab::Index kMaxParticles = 1000;
constexpr clothlab::Index kMaxParticlesGravitation = 100;
constexpr long kMaxSteps = 8;
constexpr int kMaxSolverIterations = 30;

bool has_gravitation(const clothlab::World& world) {
  for (const auto& effect : world.force_effects) {
    if (effect->name() == "gravitation") return true;
  }
  return false;
}

bool too_large_to_step(const clothlab::World& world) {
  const clothlab::Index n = world.particles.size();
  return n > kMaxParticles || (has_gravitation(world) && n > kMaxParticlesGravitation);
}

void require_finite(const clothlab::World& world) {
  if (!world.particles.x.allFinite() || !world.particles.v.allFinite()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (std::string_view method : clothlab::integrator_names()) {
    // Read afresh for each integrator: plasticity and tearing change the springs as they run.
    clothlab::Scene scene;
    try {
      scene = clothlab::parse_scene(text, "<fuzz>");
    } catch (const clothlab::SceneError&) {
      return 0;  // rejected with a message: what a malformed scene should get
    }
    if (too_large_to_step(scene.world)) return 0;
    // The scene's own integrator keeps the solver settings its [integrator] table gave.
    if (scene.world.integrator->name() != method) {
      scene.world.integrator = clothlab::make_integrator(method);
      if (!scene.world.integrator) std::abort();  // integrator_names() named a missing one
    }
    if (auto* implicit = dynamic_cast<clothlab::ImplicitEuler*>(scene.world.integrator.get())) {
      implicit->max_iterations = std::min(implicit->max_iterations, kMaxSolverIterations);
    }
    require_finite(scene.world);  // the reader must never build a non-finite state
    const long steps = std::min(scene.step_count(), kMaxSteps);
    try {
      for (long s = 0; s < steps; ++s)
        scene.world.step(scene.dt);
    } catch (const clothlab::SimulationError&) {
      continue;  // the guard stopped a blow-up and said where: also a reported error
    }
    require_finite(scene.world);
  }
  return 0;
}
