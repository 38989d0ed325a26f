// Lesson 01: explicit Euler against the lecture's symplectic Euler, measured.
//
// Three experiments, each built with the C++ API (no scene file), each with a known answer:
//   1. free fall for 1 s from rest: exactly y = -g t^2 / 2;
//   2. a mass on a spring (forces fed straight to the kernels): the energy must stay put;
//   3. two bodies orbiting each other under Newton's gravitation: the energy must stay put.
// ./build/lesson01 runs on the reference solutions, ./build/lesson01-student on your exercises;
// while an exercise is still a stub, the program names it and exits with code 4.
#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <memory>
#include <numbers>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/gravitation.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/euler.hpp"
#include "clothlab/integrators/methods.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

constexpr double g = 9.8;  // gravitational acceleration near the ground [m/s^2]

// --- 1. Free fall ---------------------------------------------------------------------------

// Height [m] after t [s] of a 1 kg particle dropped from rest at y = 0, stepped with dt [s].
double fall(std::string_view method, double dt, double t) {
  World world;
  world.integrator = make_integrator(method);
  world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0.0, -g, 0.0)));
  world.particles.add(Vec3::Zero(), Vec3::Zero(), 1.0);
  const long n = std::lround(t / dt);
  for (long k = 0; k < n; ++k) {
    world.step(dt);
  }
  return world.particles.x(1, 0);
}

void free_fall_table() {
  const double t = 1.0;
  const double exact = -0.5 * g * t * t;  // -4.9 m
  fmt::print("1. Free fall from rest for t = 1 s (exact y = -g t^2/2 = {} m)\n", exact);
  fmt::print("   {:>6}  {:>22}  {:>22}  {:>12}\n", "dt [s]", "explicit: y - exact [m]",
             "symplectic: y - exact [m]", "g dt t/2 [m]");
  for (const double dt : {0.1, 0.05, 0.01}) {
    const double error_explicit = fall("explicit-euler", dt, t) - exact;
    const double error_symplectic = fall("symplectic-euler", dt, t) - exact;
    fmt::print("   {:>6}  {:>+22.6f}  {:>+22.6f}  {:>12.6f}\n", dt, error_explicit,
               error_symplectic, 0.5 * g * dt * t);
  }
  fmt::print(
      "   First order: halve dt, halve the error. Explicit Euler lags behind (+),\n"
      "   symplectic Euler runs ahead (-), by the same g dt t/2.\n\n");
}

// --- 2. A mass on a spring ------------------------------------------------------------------

// Both kernels share this signature, so an experiment can take either one.
using Kernel = PointState (*)(const Vec3&, const Vec3&, const Vec3&, double, double);

void spring_table() {
  // m = 1 kg, k = (2 pi)^2 N/m: w = sqrt(k/m) = 2 pi rad/s, a period of 1 s. Start at x = 1 m.
  const double k = 4.0 * std::numbers::pi * std::numbers::pi;  // spring constant [N/m]
  const double dt = 0.01;                                      // [s]
  const long n = 1000;                                         // 10 periods
  const double hw = dt * 2.0 * std::numbers::pi;               // h w, dimensionless
  const auto energy = [k](const Vec3& r, const Vec3& v) {      // E = (m v^2 + k x^2)/2 [J]
    return 0.5 * v.squaredNorm() + 0.5 * k * r.squaredNorm();
  };
  fmt::print("2. Mass on a spring, period 1 s, dt = {} s (h w = {:.4f}), {} steps\n", dt, hw, n);
  fmt::print("   {:>16}  {:>14}  {:>18}\n", "method", "E_end / E_0", "largest |E/E_0 - 1|");
  const std::array<std::pair<std::string_view, Kernel>, 2> methods = {
      {{"explicit-euler", explicit_euler_step}, {"symplectic-euler", symplectic_euler_step}}};
  for (const auto& [name, step] : methods) {
    Vec3 r(1.0, 0.0, 0.0), v = Vec3::Zero();
    const double e0 = energy(r, v);
    double worst = 0.0;
    for (long s = 0; s < n; ++s) {
      const PointState next = step(r, v, -k * r, 1.0, dt);  // Hooke: f = -k x, 1/m = 1
      r = next.r;
      v = next.v;
      worst = std::max(worst, std::abs(energy(r, v) / e0 - 1.0));
    }
    fmt::print("   {:>16}  {:>14.4f}  {:>18.4f}\n", name, energy(r, v) / e0, worst);
  }
  fmt::print(
      "   Explicit Euler multiplies E by 1 + (h w)^2 each step: (1 + {:.6f})^{} = {:.4f}\n\n",
      hw * hw, n, std::pow(1.0 + hw * hw, static_cast<double>(n)));
}

// --- 3. Two bodies under Newton's gravitation -----------------------------------------------

// The orbit of two-bodies.toml: 3e9 kg and 1e9 kg, 10 m apart, centre of mass at rest at the
// origin; relative speed 0.148 m/s, 0.906 of the circular sqrt(G M / r) = 0.1634 m/s. Vis-viva
// gives the semi-major axis a = 8.479 m, and Kepler the period T = 2 pi sqrt(a^3 / (G M)).
World two_bodies(std::string_view method) {
  World world;
  world.integrator = make_integrator(method);
  world.force_effects.push_back(std::make_unique<Gravitation>(kGravitationalConstant));
  world.particles.add(Vec3(-2.5, 0.0, 0.0), Vec3(0.0, -0.037, 0.0), 3e9);
  world.particles.add(Vec3(7.5, 0.0, 0.0), Vec3(0.0, 0.111, 0.0), 1e9);
  return world;
}

void orbit_table() {
  constexpr double period = 300.27;  // T [s], as worked out above two_bodies()
  constexpr int orbits = 5;
  const double dt = 1.0;  // [s]: about 300 steps an orbit, coarse on purpose
  struct Row {
    double drift;   // (E - E_0) / |E_0| at the end of the orbit: > 0 means energy gained
    double worst;   // largest |E - E_0| / |E_0| during the orbit
    double widest;  // largest distance between the bodies during the orbit [m]
  };
  std::array<std::array<Row, orbits>, 2> rows{};
  const std::array<std::string_view, 2> methods = {"explicit-euler", "symplectic-euler"};
  for (std::size_t m = 0; m < methods.size(); ++m) {
    World world = two_bodies(methods[m]);
    const double e0 = world.kinetic_energy() + world.potential_energy();  // < 0: a bound orbit
    for (int orbit = 1; orbit <= orbits; ++orbit) {
      Row row{};
      while (world.t < orbit * period - 0.5 * dt) {
        world.step(dt);
        row.drift = (world.kinetic_energy() + world.potential_energy() - e0) / std::abs(e0);
        row.worst = std::max(row.worst, std::abs(row.drift));
        row.widest =
            std::max(row.widest, (world.particles.x.col(1) - world.particles.x.col(0)).norm());
      }
      rows[m][orbit - 1] = row;
    }
  }
  fmt::print("3. Two bodies, 3e9 kg and 1e9 kg, 10 m apart at the start, period {} s, dt = {} s\n",
             period, dt);
  fmt::print("   {:>5}  {:-^38}  {:-^38}\n", "", " explicit-euler ", " symplectic-euler ");
  fmt::print("   {:>5}", "orbit");
  for (std::size_t m = 0; m < methods.size(); ++m) {
    fmt::print("  {:>12}  {:>12}  {:>10}", "dE at end", "max |dE|", "widest [m]");
  }
  fmt::print("\n");
  for (int orbit = 0; orbit < orbits; ++orbit) {
    fmt::print("   {:>5}", orbit + 1);
    for (const auto& method_rows : rows) {
      const Row& row = method_rows[orbit];
      fmt::print("  {:>+12.2e}  {:>12.2e}  {:>10.3f}", row.drift, row.worst, row.widest);
    }
    fmt::print("\n");
  }
  fmt::print(
      "   dE = (E - E_0) / |E_0|, > 0 when energy is gained. Explicit Euler gains energy and\n"
      "   the bodies drift apart; symplectic Euler's energy wobbles but does not grow.\n");
}

}  // namespace

int main() {
  return lesson::run("lesson01", [&] {
    free_fall_table();
    spring_table();
    orbit_table();
  });
}
