// bench.cpp: `clothlab bench boundary`.
//
// The engine's hot loops call the exercise kernels (gravity_force, symplectic_euler_step), which
// live in another file, exercises/ or solutions/. Without help from the compiler every particle
// would pay for two out-of-line calls and could not be vectorised. Link-time optimisation
// inlines the kernels across that boundary. This benchmark measures the engine's step against
// the same passes with the kernels' arithmetic written inline here, in one run, and prints the
// ratio: close to 1 means the boundary costs nothing.
#include "app/bench.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "app/build_info.hpp"
#include "clothlab/euler.hpp"
#include "clothlab/gravity.hpp"
#include "clothlab/world.hpp"

namespace clothlab::app {

namespace {

World make_world(Index n) {
  World world;
  for (Index i = 0; i < n; ++i) {
    world.particles.add(Vec3(0.001 * i, 1000.0, 0.0), Vec3(1.0, 0.0, 0.0), 0.5 + 1e-3 * i);
  }
  world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0, -9.8, 0)));
  world.integrator = std::make_unique<SymplecticEuler>();
  world.guard.max_position = 1e12;
  return world;
}

// The engine's step, pass for pass, with the kernels' arithmetic written inline in this file:
// clear the forces, add gravity, move with symplectic Euler, run the guard's checks.
void inline_step(Particles& p, const Vec3& g, double dt, const Guard& guard) {
  p.f.setZero();
  for (Index i = 0; i < p.size(); ++i)
    p.f.col(i) += p.m[i] * g;
  for (Index i = 0; i < p.size(); ++i) {
    p.v.col(i) += p.f.col(i) * p.inv_m[i] * dt;
    p.x.col(i) += p.v.col(i) * dt;
  }
  if (!(p.x.array().abs() <= guard.max_position).all() ||
      !(p.v.array().abs() <= guard.max_speed).all()) {
    throw std::runtime_error("bench: the inline world blew up");
  }
}

// What the same physics costs in one fused loop: a hint of what a data-oriented fast path can
// gain over the step a lesson reads (see lesson 01 and, later, the performance work).
void fused_step(Particles& p, const Vec3& g, double dt) {
  for (Index i = 0; i < p.size(); ++i) {
    p.v.col(i) += g * dt;  // f / m = m g / m = g
    p.x.col(i) += p.v.col(i) * dt;
  }
}

// Median over `repeats` of the wall time of `steps` calls to step(), in ns per particle-step.
template <class Step>
double measure(Index n, long steps, int repeats, Step step) {
  std::vector<double> samples;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    for (long s = 0; s < steps; ++s)
      step();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    samples.push_back(1e9 * seconds / (static_cast<double>(n) * static_cast<double>(steps)));
  }
  std::nth_element(samples.begin(), samples.begin() + repeats / 2, samples.end());
  return samples[static_cast<size_t>(repeats / 2)];
}

void bench_boundary(Index n, long steps, int repeats) {
  const double dt = 1e-4;
  World engine = make_world(n);
  World inline_world = make_world(n);
  World fused_world = make_world(n);
  const Vec3 g(0, -9.8, 0);
  const double t_engine = measure(n, steps, repeats, [&] { engine.step(dt); });
  const double t_inline =
      measure(n, steps, repeats, [&] { inline_step(inline_world.particles, g, dt, engine.guard); });
  const double t_fused =
      measure(n, steps, repeats, [&] { fused_step(fused_world.particles, g, dt); });
  // The two worlds took the same steps: their states must agree, or the figures compare
  // different work. (Equal to rounding: the compiler may order the arithmetic differently.)
  const double gap = (engine.particles.x - inline_world.particles.x).cwiseAbs().maxCoeff();

  fmt::print("bench boundary: {} particles, gravity + symplectic Euler, {} steps, median of {}\n",
             n, steps, repeats);
  fmt::print(
      "  engine step (kernels from {}, {}):  {:7.3f} ns per particle-step\n", kKernels,
      kLinkTimeOptimised ? "inlined by link-time optimisation" : "link-time optimisation off",
      t_engine);
  fmt::print("  the same passes, kernels written inline here:      {:7.3f} ns per particle-step\n",
             t_inline);
  fmt::print(
      "  ratio engine / inline: {:.2f}   (1.00 = the boundary costs nothing; largest "
      "position gap {:.3g} m)\n",
      t_engine / t_inline, gap);
  fmt::print(
      "  for scale, one fused loop (no force array, no guard): {:7.3f} ns, engine / fused "
      "{:.2f}\n",
      t_fused, t_engine / t_fused);
}

}  // namespace

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Measure the engine (figures and ratios)");
  bench->require_subcommand(1);
  CLI::App* boundary = bench->add_subcommand(
      "boundary", "Engine step with exercise kernels vs the same loop written inline");
  static Index n = 10000;
  static long steps = 2000;
  static int repeats = 5;
  boundary->add_option("--particles", n, "Particles")->check(CLI::PositiveNumber);
  boundary->add_option("--steps", steps, "Steps per repeat")->check(CLI::PositiveNumber);
  boundary->add_option("--repeats", repeats, "Repeats (median is shown)")
      ->check(CLI::PositiveNumber);
  boundary->callback([] { bench_boundary(n, steps, repeats); });
}

}  // namespace clothlab::app
