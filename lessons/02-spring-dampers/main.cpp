// Lesson 02: spring-dampers, from one spring to a small hanging cloth, each against a known answer.
//
// Four experiments, each built with the C++ API (no scene file):
//   0. one spring-damper force worked by hand: 8.8 N along e;
//   1. a mass bobbing on a spring: its period must be 2 pi sqrt(m / ks), its centre m g / ks down;
//   2. a damped spring: the energy at each turning point must fall, by exp(-kd T_d / (2 m));
//   3. a small cloth: springs alone keep its momentum; hung from two corners, it settles.
// ./build/lesson02 runs on the reference solutions, ./build/lesson02-student on your exercises;
// while an exercise is still a stub, the program names it and exits with code 4.
#include <algorithm>
#include <cmath>
#include <exception>
#include <memory>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/methods.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

constexpr double g = 9.8;    // gravitational acceleration [m/s^2]
constexpr double m = 1.0;    // mass of the bob in experiments 1 and 2 [kg]
constexpr double dt = 1e-3;  // time step of experiments 1 and 2 [s]
constexpr double pi = std::numbers::pi;

// Particle 0 pinned at the origin, particle 1 (the bob, m kg) at `bob`, one spring-damper.
World one_spring(double ks, double kd, double l0, const Vec3& bob, bool gravity) {
  World world;
  world.integrator = make_integrator("symplectic-euler");
  Particles& p = world.particles;
  pin(p, p.add(Vec3::Zero(), Vec3::Zero(), 1.0));  // 1/m = 0 and v = 0: it never moves
  p.add(bob, Vec3::Zero(), m);
  SpringSet springs;
  springs.add(0, 1, ks, kd, l0);
  world.force_effects.push_back(std::make_unique<SpringDampers>("springs", std::move(springs)));
  if (gravity) world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0, -g, 0)));
  return world;
}

void worked_force() {
  // l = |(0.3, 0.4, 0)| = 0.5 m, e = (0.6, 0.8, 0); v1 along e = 0.6 m/s, v2 along e = 0;
  // f_sd = -100 (0.4 - 0.5) - 2 (0.6 - 0) = 10 - 1.2 = 8.8 N; f1 = 8.8 e = (5.28, 7.04, 0) N.
  const Vec3 f1 = spring_damper_force(Vec3::Zero(), Vec3(0.3, 0.4, 0), Vec3(1, 0, 0), Vec3::Zero(),
                                      100.0, 2.0, 0.4);
  fmt::print("0. One spring-damper: ks = 100 N/m, kd = 2 N s/m, l0 = 0.4 m, l = 0.5 m\n");
  fmt::print("   f1 = ({:.4f}, {:.4f}, {:.4f}) N; by hand 8.8 e = (5.2800, 7.0400, 0.0000) N\n\n",
             f1.x(), f1.y(), f1.z());
}

// --- 1. The period of a mass on a spring ----------------------------------------------------

void period_table() {
  fmt::print("1. A 1 kg bob hanging on one spring, released at rest length, dt = {} s, 5 s\n", dt);
  fmt::print("   {:>8}  {:>12}  {:>12}  {:>12}  {:>12}\n", "ks [N/m]", "2pi sqrt(m/k)",
             "measured T", "m g / ks [m]", "centre [m]");
  for (const double ks : {25.0, 100.0, 400.0}) {
    World world = one_spring(ks, 0.0, 1.0, Vec3(0, -1, 0), true);  // released at rest length
    const double y_eq = -1.0 - m * g / ks;                         // equilibrium height [m]
    std::vector<double> crossings;  // times the bob passes y_eq going down [s]
    double y_low = 0.0, y_high = -1.0;
    double y_prev = world.particles.x(1, 1);
    while (world.t < 5.0) {
      world.step(dt);
      const double y = world.particles.x(1, 1);
      if (y_prev > y_eq && y <= y_eq)  // interpolate the crossing inside the step
        crossings.push_back(world.t - dt * (y_eq - y) / (y_prev - y));
      y_low = std::min(y_low, y);
      y_high = std::max(y_high, y);
      y_prev = y;
    }
    const double T = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
    const double centre = -1.0 - 0.5 * (y_low + y_high);  // stretch at the middle of the swing
    fmt::print("   {:>8}  {:>12.6f}  {:>12.6f}  {:>12.6f}  {:>12.6f}\n", ks,
               2 * pi * std::sqrt(m / ks), T, m * g / ks, centre);
  }
  fmt::print(
      "   Gravity moves the centre of the swing down by m g / ks; the period does not care.\n\n");
}

// --- 2. A damped spring ---------------------------------------------------------------------

void damping_table() {
  const double ks = 100.0;  // [N/m]: w = 10 rad/s
  fmt::print("2. A 1 kg bob on a spring of 100 N/m stretched 0.1 m, no gravity, 3 s\n");
  fmt::print("   {:>11}  {:>14}  {:>20}  {:>16}  {:>16}\n", "kd [N s/m]", "turning points",
             "E ratio per half T", "exp(-kd T_d/2m)", "largest rise [J]");
  for (const double kd : {0.0, 0.5, 2.0}) {
    World world = one_spring(ks, kd, 1.0, Vec3(1.1, 0, 0), false);
    std::vector<double> energy_at_turns;  // E = K + U where the bob stops and turns [J]
    double v_prev = 0.0;
    while (world.t < 3.0) {
      world.step(dt);
      const double v = world.particles.v(0, 1);
      if (v_prev != 0.0 && (v > 0) != (v_prev > 0))
        energy_at_turns.push_back(world.kinetic_energy() + world.potential_energy());
      v_prev = v;
    }
    double rise = 0.0;  // largest gain from one turning point to the next [J]: a damper adds none
    for (size_t k = 1; k < energy_at_turns.size(); ++k)
      rise = std::max(rise, energy_at_turns[k] - energy_at_turns[k - 1]);
    const double n = double(energy_at_turns.size() - 1);  // half periods between first and last
    const double ratio = std::pow(energy_at_turns.back() / energy_at_turns.front(), 1.0 / n);
    const double w_d = std::sqrt(ks / m - std::pow(kd / (2 * m), 2));  // damped frequency [rad/s]
    fmt::print("   {:>11}  {:>14}  {:>20.4f}  {:>16.4f}  {:>16.1e}\n", kd, energy_at_turns.size(),
               ratio, std::exp(-kd * (pi / w_d) / m), rise);
  }
  fmt::print(
      "   Between turning points (half a period T_d/2 apart) the amplitude shrinks by\n"
      "   exp(-kd T_d / 4m) and the energy, which goes with its square, by exp(-kd T_d / 2m).\n\n");
}

// --- 3. A small cloth -----------------------------------------------------------------------

// A 10 x 10 cloth, 0.1 m apart, 0.1 kg, with structural and shear spring-dampers.
World small_cloth(bool hanging) {
  World world;
  world.integrator = make_integrator("symplectic-euler");
  ClothSpec spec;
  spec.rows = spec.cols = 10;
  spec.spacing = 0.1;  // [m]
  spec.mass = 0.1;     // [kg], 1 g a particle
  const ClothGrid grid = add_cloth(world.particles, spec);
  SpringSet springs;
  const Matrix3X& x = world.particles.x;
  add_spring_family(springs, structural_pairs(grid.rows, grid.cols), grid.first, 100.0, 0.2, x);
  add_spring_family(springs, shear_pairs(grid.rows, grid.cols), grid.first, 20.0, 0.2, x);
  world.force_effects.push_back(std::make_unique<SpringDampers>("springs", std::move(springs)));
  if (hanging) {
    world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0, -g, 0)));
    pin(world.particles, grid.at(0, 0));
    pin(world.particles, grid.at(0, grid.cols - 1));
  }
  return world;
}

void cloth_tables() {
  const double h = 2e-4;  // [s]: 1 g particles need a short step (see the lesson)
  World free = small_cloth(false);
  std::mt19937 rng(2);  // fixed seed: the same kick on every run
  for (Index i = 0; i < free.particles.size(); ++i) {
    for (int d = 0; d < 3; ++d)
      free.particles.v(d, i) = 2.0 * rng() / double(rng.max()) - 1.0;
  }
  const Vec3 p0 = free.momentum();
  const double e0 = free.kinetic_energy() + free.potential_energy();
  double drift = 0.0;  // largest |P - P0| [kg m/s]
  while (free.t < 1.0) {
    free.step(h);
    drift = std::max(drift, (free.momentum() - p0).norm());
  }
  const double k_cm = 0.5 * p0.squaredNorm() / free.particles.m.sum();  // |P|^2 / 2M [J]
  fmt::print("3. A 10 x 10 cloth of 0.1 kg, springs only, every particle kicked at random, 1 s\n");
  fmt::print("   momentum P0 = ({:.6f}, {:.6f}, {:.6f}) kg m/s; largest |P - P0| = {:.1e} kg m/s\n",
             p0.x(), p0.y(), p0.z(), drift);
  fmt::print(
      "   energy {:.4f} J -> {:.4f} J, of which no damper can take the P0^2/2M = {:.4f} J\n\n", e0,
      free.kinetic_energy() + free.potential_energy(), k_cm);

  World hung = small_cloth(true);
  fmt::print("   The same cloth pinned at its two top corners, under gravity, from rest:\n");
  fmt::print("   {:>12}  {:>16}  {:>16}\n", "window [s]", "largest K [J]", "lowest y [m]");
  for (double end = 0.5; end <= 3.0 + 1e-9; end += 0.5) {
    double k_max = 0.0, y_low = 0.0;
    while (hung.t < end - 0.5 * h) {
      hung.step(h);
      k_max = std::max(k_max, hung.kinetic_energy());
      y_low = std::min(y_low, hung.particles.x.row(1).minCoeff());
    }
    fmt::print("   {:>5.1f} - {:<4.1f}  {:>16.3e}  {:>16.5f}\n", end - 0.5, end, k_max, y_low);
  }
  fmt::print("   The bounce dies away and the cloth comes to rest, sagging under its weight.\n");
}

}  // namespace

int main() {
  return lesson::run("lesson02", [&] {
    worked_force();
    period_table();
    damping_table();
    cloth_tables();
  });
}
