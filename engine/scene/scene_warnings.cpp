#include "scene/scene_warnings.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <vector>

#include <fmt/format.h>

#include "clothlab/after_step/ground_collision.hpp"

namespace clothlab {

CoincidentParticles find_coincident_particles(const Matrix3X& x) {
  std::vector<Index> order(static_cast<size_t>(x.cols()));
  std::iota(order.begin(), order.end(), Index{0});
  // By position (x, then y, then z), then by number: equal positions end up side by side, each
  // run of them starting with its lowest-numbered particle. (-0.0 == 0.0, as for the forces.)
  std::sort(order.begin(), order.end(), [&](Index a, Index b) {
    for (int c = 0; c < 3; ++c) {
      if (x(c, a) != x(c, b)) return x(c, a) < x(c, b);
    }
    return a < b;
  });
  CoincidentParticles found;
  Index run_first = order.empty() ? -1 : order[0];  // the lowest-numbered particle of this run
  for (size_t k = 1; k < order.size(); ++k) {
    if (x.col(order[k]) != x.col(order[k - 1])) {
      run_first = order[k];
      continue;
    }
    ++found.count;
    if (found.second < 0 || order[k] < found.second) {
      found.first = run_first;
      found.second = order[k];
    }
  }
  return found;
}

std::vector<StartInside> find_particles_inside(const World& world) {
  const Particles& p = world.particles;
  std::vector<StartInside> found;
  for (const auto& effect : world.post_step_effects) {
    // depth(x) > 0: how far x is inside the collider [m], as its collide() measures it.
    std::function<double(const Vec3&)> depth;
    StartInside inside;
    if (const auto* ground = dynamic_cast<const Ground*>(effect.get())) {
      depth = [y0 = ground->y0()](const Vec3& x) { return y0 - x.y(); };
      inside.what = fmt::format("the ground [ground] (y = {} m)", ground->y0());
    } else if (const auto* plane = dynamic_cast<const Plane*>(effect.get())) {
      depth = [plane](const Vec3& x) { return -(x - plane->point()).dot(plane->normal()); };
      const Vec3& a = plane->point();
      const Vec3& n = plane->normal();
      inside.what = fmt::format(
          "the [[plane]] through ({}, {}, {}) m facing ({:.3g}, {:.3g}, "
          "{:.3g})",
          a.x(), a.y(), a.z(), n.x(), n.y(), n.z());
    } else if (const auto* sphere = dynamic_cast<const Sphere*>(effect.get())) {
      depth = [sphere](const Vec3& x) { return sphere->radius() - (x - sphere->centre()).norm(); };
      const Vec3& c = sphere->centre();
      inside.what = fmt::format("the [sphere] of radius {} m about ({}, {}, {}) m",
                                sphere->radius(), c.x(), c.y(), c.z());
    } else {
      continue;
    }
    for (Index i = 0; i < p.size(); ++i) {
      const double d = depth(p.x.col(i));
      if (!(d > 0.0) || p.inv_m[i] == 0.0) continue;  // outside, or pinned: never pushed
      if (inside.count++ == 0) {
        inside.first = i;
        inside.depth = d;
      }
      inside.deepest = std::max(inside.deepest, d);
    }
    if (inside.count == 0) continue;
    inside.collider = effect.get();
    found.push_back(std::move(inside));
  }
  return found;
}

std::string describe_particle(const Scene& scene, Index i) {
  if (scene.rope && i >= scene.rope->first && i < scene.rope->first + scene.rope->count) {
    return fmt::format("the rope's particle {}", i - scene.rope->first);
  }
  if (scene.cloth && i >= scene.cloth->first && i < scene.cloth->first + scene.cloth->size()) {
    const Index local = i - scene.cloth->first;
    return fmt::format("the cloth's particle {} (row {}, column {})", local,
                       local / scene.cloth->cols, local % scene.cloth->cols);
  }
  if (scene.solid && i >= scene.solid->first && i < scene.solid->first + scene.solid->size()) {
    return fmt::format("the solid's particle {}", i - scene.solid->first);
  }
  return fmt::format("[[particle]] #{}", i + 1);  // they come first, one a table
}

std::string all_pairs_warning(const Scene& scene) {
  const World& world = scene.world;
  const Index n = world.particles.size();
  const bool gravitation =
      std::any_of(world.force_effects.begin(), world.force_effects.end(),
                  [](const auto& effect) { return effect->name() == "gravitation"; });
  if (!gravitation || n <= kAllPairsWarnAbove) return "";
  const double pairs = 0.5 * static_cast<double>(n) * static_cast<double>(n - 1);
  // Each force evaluation visits every pair; so does each potential energy, taken for the guard
  // every 32 steps and for energy.csv every frame (a frame every round(1 / (fps dt)) steps),
  // at about the same cost a pair (a square root and a division).
  const int forces = world.integrator->force_evaluations_per_step();
  const double steps_per_frame =
      static_cast<double>(std::max(1L, std::lround(1.0 / (scene.output.fps * scene.dt))));
  const double sweeps = forces + 1.0 / 32.0 + 1.0 / steps_per_frame;
  const double per_step = pairs * sweeps * kGravitationSecondsPerPair;
  const long steps = scene.step_count();
  return fmt::format(
      "[gravitation] sums over all n(n-1)/2 = {:.3g} pairs of the scene's {} particles {} a "
      "step with {}, and for the energy the guard and energy.csv take: about {} a step "
      "and {} for the run's {} steps, at {:.2g} ns a pair (measured); it is meant for a few "
      "bodies: use it on at most {} particles, or leave [gravitation] out",
      pairs, n, forces == 1 ? std::string("once") : fmt::format("{} times", forces),
      world.integrator->name(), human_duration(per_step),
      human_duration(per_step * static_cast<double>(steps)), steps,
      kGravitationSecondsPerPair * 1e9, kAllPairsWarnAbove);
}

std::string human_duration(double seconds) {
  constexpr double kMinute = 60.0, kHour = 3600.0, kDay = 86400.0, kYear = 365.25 * kDay;
  if (seconds < kMinute) return fmt::format("{:.2g} s", seconds);
  if (seconds < kHour) return fmt::format("{:.2g} min", seconds / kMinute);
  if (seconds < 2.0 * kDay) return fmt::format("{:.2g} h", seconds / kHour);
  if (seconds < kYear) return fmt::format("{:.3g} days", seconds / kDay);
  return fmt::format("{:.3g} years", seconds / kYear);
}

}  // namespace clothlab
