#include "analysis/run_cost.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "clothlab/after_step/self_collision.hpp"
#include "clothlab/after_step/strain_limiting.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/local_global.hpp"
#include "clothlab/integrators/vbd.hpp"
#include "clothlab/integrators/xpbd.hpp"
#include "scene/scene_warnings.hpp"

namespace clothlab {

namespace {

// Costs per element [s], measured with `clothlab run SCENE --stats` on a 64 x 64 cloth (4096
// particles, 16002 springs, 20 steps) on the 2-core machine of the README's Speed section, with
// other jobs running (a load of about 10): the time of the part over the count of its elements.
// XPBD, 20 substeps, 2 iterations: 0.654 s / 12.8e6 projections.
constexpr double kXpbdProjection = 51e-9;
// [strain_limit] max_strain = 1e-4, 20 sweeps: 0.319 s / 6.4e6 spring-sweeps.
constexpr double kStrainSweep = 50e-9;
// [self_collision], 4 passes at most: 0.0314 s / 81920 particle-passes (one pass a step).
constexpr double kSelfCollisionPass = 380e-9;
// local-global, 10 iterations: 0.431 s / 3.2e6 spring-iterations (the local step, the global
// solve and the factor, once, shared out).
constexpr double kLocalGlobalIteration = 135e-9;
// vbd, 10 iterations: 0.552 s / 3.2e6 spring-iterations (the median of three runs at a load of
// about 6; each spring is in the blocks of both its ends).
constexpr double kVbdIteration = 172e-9;
// implicit-euler, 50 conjugate-gradient iterations a solve: 0.931 s / 16e6 spring-iterations.
constexpr double kImplicitIteration = 58e-9;

// Bytes a row: positions.csv of a 1000 x 1000 cloth, 52 MB a frame (README's Running scenes);
// springs.csv of the 64 x 64 cloth above, 1695454 bytes for 32004 rows (two frames), 53 a row.
constexpr double kCsvParticleRow = 52.0;
constexpr double kCsvSpringRow = 53.0;
constexpr double kNpyParticle = 12.0;  // three 32-bit floats
// The implicit step's matrix: a 3 x 3 block of doubles for each particle and each spring end
// pair, twice over (the matrix and its preconditioned copy), and about ten vectors of 3 n.
constexpr double kImplicitBlockBytes = 2.0 * 9.0 * 8.0;

double count_springs(const World& world) {
  double springs = 0.0;
  for (const auto& effect : world.force_effects) {
    if (const auto* family = dynamic_cast<const SpringDampers*>(effect.get()))
      springs += static_cast<double>(family->springs().size());
  }
  return springs;
}

std::string bytes_text(double bytes) {
  if (bytes >= 1e9) return fmt::format("{:.3g} GB", bytes / 1e9);
  return fmt::format("{:.3g} MB", bytes / 1e6);
}

}  // namespace

std::vector<std::string> run_cost_warnings(const Scene& scene, bool velocities, bool springs_out,
                                           bool npy) {
  const World& world = scene.world;
  const double n = static_cast<double>(world.particles.size());
  const double springs = count_springs(world);
  const double steps = static_cast<double>(scene.step_count());
  std::vector<std::string> warnings;
  // One line for a part that will take longer than kCostWarnAboveSeconds over the run.
  const auto part = [&](const std::string& what, double per_step) {
    if (per_step * steps <= kCostWarnAboveSeconds) return;
    warnings.push_back(fmt::format(
        "{}: about {} a step and {} for the run's {:.0f} steps (measured costs per element, "
        "engine/analysis/run_cost.cpp); make the scene smaller, or ask for less",
        what, human_duration(per_step), human_duration(per_step * steps), steps));
  };

  if (const auto* xpbd = dynamic_cast<const Xpbd*>(world.integrator.get())) {
    const double projections = springs * xpbd->substeps * xpbd->iterations;
    part(fmt::format("XPBD projects {:.3g} constraints a step ({:.0f} springs x {} substeps x {} "
                     "iterations)",
                     projections, springs, xpbd->substeps, xpbd->iterations),
         projections * kXpbdProjection);
  } else if (const auto* local = dynamic_cast<const LocalGlobal*>(world.integrator.get())) {
    part(fmt::format("the local/global solver takes {} iterations a step over {:.0f} springs "
                     "(and factors its matrix of {:.0f} particles)",
                     local->iterations, springs, n),
         springs * local->iterations * kLocalGlobalIteration);
  } else if (const auto* vbd = dynamic_cast<const Vbd*>(world.integrator.get())) {
    part(fmt::format("vertex block descent takes {} iterations a step over {:.0f} springs",
                     vbd->iterations, springs),
         springs * vbd->iterations * kVbdIteration);
  } else if (const auto* implicit = dynamic_cast<const ImplicitEuler*>(world.integrator.get())) {
    part(fmt::format("implicit Euler's solve takes up to {} conjugate-gradient iterations a step "
                     "over {:.0f} springs",
                     implicit->max_iterations, springs),
         springs * implicit->max_iterations * kImplicitIteration);
    const double memory = (n + springs) * kImplicitBlockBytes + 10.0 * 3.0 * n * 8.0;
    if (memory > kOutputWarnAboveBytes) {
      warnings.push_back(fmt::format(
          "implicit Euler's matrix for {:.0f} particles and {:.0f} springs takes about {} of "
          "memory",
          n, springs, bytes_text(memory)));
    }
  }
  for (const auto& effect : world.post_step_effects) {
    if (const auto* limit = dynamic_cast<const StrainLimiting*>(effect.get())) {
      part(fmt::format("[strain_limit] sweeps {:.0f} springs up to {} times a step", springs,
                       limit->iterations()),
           springs * limit->iterations() * kStrainSweep);
    } else if (const auto* self = dynamic_cast<const SelfCollision*>(effect.get())) {
      part(fmt::format("[self_collision] checks {:.0f} particles for pairs up to {} times a step",
                       n, self->iterations()),
           n * self->iterations() * kSelfCollisionPass);
    }
  }

  // The files: a frame every round(1 / (fps dt)) steps (io/run.cpp), the first and the last.
  const double frame_steps =
      std::clamp(std::round(1.0 / (scene.output.fps * scene.dt)), 1.0, std::max(steps, 1.0));
  const double frames = 1.0 + std::ceil(steps / frame_steps);
  const double particle_file = npy ? kNpyParticle : kCsvParticleRow;
  const double per_frame =
      n * particle_file * (velocities ? 2.0 : 1.0) + (springs_out ? springs * kCsvSpringRow : 0.0);
  const double total = per_frame * frames;
  if (total > kOutputWarnAboveBytes) {
    warnings.push_back(fmt::format(
        "the run will write about {} ({:.0f} frames of {}){}; lower [output] fps, or choose "
        "format = \"npy\" (12 bytes a particle, not about 52)",
        bytes_text(total), frames, bytes_text(per_frame), npy ? "" : ", in CSV files"));
  }
  return warnings;
}

}  // namespace clothlab
