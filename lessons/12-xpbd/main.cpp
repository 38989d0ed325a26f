// Lesson 12: position-based dynamics and XPBD. Measures what the lesson's README quotes:
//   1. one mass on one constraint (hanging-mass.toml): where it settles with XPBD and with plain
//      PBD (lambda forgotten), for 1 and 10 iterations and three steps, against m g / ks;
//   2. a chain of four links: the same, where one iteration no longer solves the constraints;
//   3. a spring pendulum: XPBD's error against a force-based reference as the substeps grow,
//      beside symplectic Euler at the same small step;
//   4. stiff-curtain.toml (lesson 08's stiff sheet) at 1/60 s: symplectic Euler, and XPBD with
//      the same work spent on substeps or on iterations: stretch, energy and wall time.
// ./build/lesson12 runs on the reference solutions, ./build/lesson12-student on your exercises
// (it needs those of lessons 01 to 03 and 07 as well); while one is still a stub, the program
// names it and exits with code 4.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/guard.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/methods.hpp"
#include "clothlab/integrators/xpbd.hpp"
#include "scene/scene.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

constexpr double kG = 9.8;  // [m/s^2]

std::unique_ptr<Xpbd> xpbd(int substeps, int iterations, bool keep_lambda = true) {
  auto integrator = std::make_unique<Xpbd>();
  integrator->substeps = substeps;
  integrator->iterations = iterations;
  integrator->keep_lambda = keep_lambda;
  return integrator;
}

// A chain of `links` springs (ks [N/m], kd [N s/m], l0 = 1 m) hanging down -y from a pinned
// particle at the origin, each free particle of mass m [kg], under gravity, at rest.
World chain(int links, double m, double ks, double kd) {
  World world;
  world.particles.add(Vec3::Zero(), Vec3::Zero(), m);
  pin(world.particles, 0);
  SpringSet springs;
  for (int k = 1; k <= links; ++k) {
    world.particles.add(Vec3(0.0, -k, 0.0), Vec3::Zero(), m);
    springs.add(k - 1, k, ks, kd, 1.0);
  }
  world.force_effects.push_back(std::make_unique<SpringDampers>("springs", std::move(springs)));
  world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0.0, -kG, 0.0)));
  return world;
}

// How far the bottom of a chain of `links` hangs below its rest position after `seconds` [m].
double settled_sag(int links, double dt, int iterations, bool keep_lambda, double seconds) {
  World world = chain(links, 0.1, 100.0, 0.5);
  world.integrator = xpbd(10, iterations, keep_lambda);
  const long steps = std::lround(seconds / dt);
  for (long s = 0; s < steps; ++s)
    world.step(dt);
  return -static_cast<double>(links) - world.particles.x(1, links);
}

void hanging_mass() {
  fmt::print(
      "1. One mass (0.1 kg) on one constraint (ks = 100 N/m), 10 substeps a step, after 10 s:\n"
      "   the spring's static stretch is m g / ks = {:.2f} mm\n",
      0.1 * kG / 100.0 * 1e3);
  fmt::print("   {:>10}  {:>14}  {:>14}  {:>14}  {:>14}\n", "dt [s]", "XPBD 1 it [mm]",
             "XPBD 10 it [mm]", "PBD 1 it [mm]", "PBD 10 it [mm]");
  for (double dt : {1.0 / 30.0, 1.0 / 60.0, 1.0 / 240.0}) {
    fmt::print("   {:>10.5f}  {:>14.4f}  {:>14.4f}  {:>14.4f}  {:>14.4f}\n", dt,
               settled_sag(1, dt, 1, true, 10.0) * 1e3, settled_sag(1, dt, 10, true, 10.0) * 1e3,
               settled_sag(1, dt, 1, false, 10.0) * 1e3, settled_sag(1, dt, 10, false, 10.0) * 1e3);
  }
  fmt::print("\n");
}

void hanging_chain() {
  fmt::print(
      "2. A chain of four links, 0.1 kg a particle, ks = 100 N/m, dt = 1/60 s, 10 substeps,\n"
      "   after 20 s: its bottom hangs (4 + 3 + 2 + 1) m g / ks = {:.1f} mm below its rest place\n",
      10 * 0.1 * kG / 100.0 * 1e3);
  fmt::print("   {:>10}  {:>12}  {:>12}\n", "iterations", "XPBD [mm]", "PBD [mm]");
  for (int iterations : {1, 2, 5, 10, 50}) {
    fmt::print("   {:>10}  {:>12.2f}  {:>12.2f}\n", iterations,
               settled_sag(4, 1.0 / 60.0, iterations, true, 20.0) * 1e3,
               settled_sag(4, 1.0 / 60.0, iterations, false, 20.0) * 1e3);
  }
  fmt::print("\n");
}

// A 1 kg bob on a spring (ks = 1000 N/m, l0 = 1 m) from a pinned anchor, released from rest
// level with it, under gravity: where it is after 1 s.
Vec3 pendulum_after_one_second(std::unique_ptr<Integrator> integrator, double dt) {
  World world = chain(1, 1.0, 1000.0, 0.0);
  world.particles.x.col(1) = Vec3(1.0, 0.0, 0.0);  // level with the anchor, at rest length
  world.integrator = std::move(integrator);
  const long steps = std::lround(1.0 / dt);
  for (long s = 0; s < steps; ++s)
    world.step(dt);
  return world.particles.x.col(1);
}

void convergence() {
  fmt::print(
      "3. A spring pendulum (1 kg, ks = 1000 N/m, released level with its anchor) after 1 s:\n"
      "   distance from RK4 at dt = 1e-5 s; XPBD at dt = 1/60 s with n substeps, and symplectic\n"
      "   Euler (force-based) at the same small step dt / n\n");
  const Vec3 reference = pendulum_after_one_second(make_integrator("rk4"), 1e-5);
  fmt::print("   {:>9}  {:>10}  {:>14}  {:>20}\n", "substeps", "dt_s [ms]", "XPBD error [m]",
             "sympl. Euler error [m]");
  for (int n : {1, 4, 16, 64, 256}) {
    const double dt = 1.0 / 60.0;
    const double e_xpbd = (pendulum_after_one_second(xpbd(n, 1), dt) - reference).norm();
    std::string e_euler = "blows up";
    try {
      const Vec3 x = pendulum_after_one_second(make_integrator("symplectic-euler"), dt / n);
      e_euler = fmt::format("{:.6f}", (x - reference).norm());
    } catch (const SimulationError&) {
    }
    fmt::print("   {:>9}  {:>10.4f}  {:>14.6f}  {:>20}\n", n, dt / n * 1e3, e_xpbd, e_euler);
  }
  fmt::print("\n");
}

void stiff_curtain() {
  fmt::print(
      "4. stiff-curtain.toml: lesson 08's stiff sheet (ks = 20000 N/m) at dt = 1/60 s for 4 s\n");
  fmt::print("   {:<34}  {:>14}  {:>12}  {:>10}\n", "method", "largest strain", "energy [J]",
             "wall [s]");
  struct Variant {
    const char* name;
    std::string method;
    int substeps, iterations;
  };
  const Variant variants[] = {{"symplectic Euler", "symplectic-euler", 1, 1},
                              {"XPBD, 20 substeps x 1 iteration", "xpbd", 20, 1},
                              {"XPBD, 1 substep x 20 iterations", "xpbd", 1, 20},
                              {"XPBD, 5 substeps x 4 iterations", "xpbd", 5, 4},
                              {"XPBD, 100 substeps x 1 iteration", "xpbd", 100, 1}};
  for (const Variant& v : variants) {
    Scene scene = load_scene_file(lesson_file("stiff-curtain.toml"));
    scene.world.integrator = make_integrator(v.method);
    if (auto* x = dynamic_cast<Xpbd*>(scene.world.integrator.get())) {
      x->substeps = v.substeps;
      x->iterations = v.iterations;
    }
    const Clock::time_point start = Clock::now();
    try {
      for (long s = 0; s < scene.step_count(); ++s)
        scene.world.step(scene.dt);
    } catch (const SimulationError& error) {
      fmt::print("   {:<34}  stopped by the guard at step {}\n", v.name, error.step());
      continue;
    }
    fmt::print("   {:<34}  {:>13.3f}%  {:>12.4f}  {:>10.2f}\n", v.name,
               largest_strain(scene.world) * 100.0, energy(scene.world), seconds_since(start));
  }
}

}  // namespace

int main() {
  return lesson::run("lesson12", [&] {
    hanging_mass();
    hanging_chain();
    convergence();
    stiff_curtain();
  });
}
