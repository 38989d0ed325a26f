// Lesson 14: Vertex Block Descent. Measures what the lesson's README quotes:
//   1. one mass on one spring (hanging-mass.toml): its first step against the Newton step worked
//      by hand, and where it settles, against m g / ks;
//   2. the sweeps close in on implicit Euler's step: one step of swinging-chain.toml after 1 to
//      100 iterations against the converged one, and where each iteration count ends;
//   3. lesson 08's stiff sheet at 1/60 s (stiff-sheet.toml): largest strain and energy after 4 s
//      for 1, 10 and 100 iterations, from each initial guess, against implicit Euler;
//   4. a sheet scrambled at random (scrambled-sheet.toml) pulls itself flat.
// ./build/lesson14 runs on the reference solutions, ./build/lesson14-student on your exercises
// (it needs those of lessons 01 to 03 as well: gravity, the springs' energy, the aerodynamic
// force); while one is still a stub, the program names it and exits with code 4.
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/core/guard.hpp"
#include "clothlab/integrators/methods.hpp"
#include "clothlab/integrators/vbd.hpp"
#include "scene/scene.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

// The scene `name` of this lesson, stepped by VBD with `iterations` sweeps from `guess`.
Scene vbd_scene(const char* name, int iterations,
                VbdInitialGuess guess = VbdInitialGuess::inertia) {
  Scene scene = load_scene_file(lesson_file(name));
  auto vbd = std::make_unique<Vbd>();
  vbd->iterations = iterations;
  vbd->initial_guess = guess;
  scene.world.integrator = std::move(vbd);
  return scene;
}

void hanging_mass() {
  // The worked example: from y = x + h^2 g, one Newton step along the spring lands at
  // m g / (m/h^2 + ks + kd/h) below the rest length.
  const double m = 0.1, ks = 100.0, kd = 0.5, g = 9.8, h = 1.0 / 60.0;
  fmt::print(
      "1. hanging-mass.toml: 0.1 kg on ks = 100 N/m (kd = 0.5 N s/m) at h = 1/60 s. By hand, the\n"
      "   first step ends m g / (m/h^2 + ks + kd/h) = {:.4f} mm below the rest length; the\n"
      "   static stretch is m g / ks = {:.4f} mm\n",
      m * g / (m / (h * h) + ks + kd / h) * 1e3, m * g / ks * 1e3);
  fmt::print("   {:>10}  {:>16}  {:>16}\n", "iterations", "first step [mm]", "after 10 s [mm]");
  for (int iterations : {1, 10}) {
    Scene scene = vbd_scene("hanging-mass.toml", iterations);
    scene.world.step(scene.dt);
    const double first = -1.0 - scene.world.particles.x(1, 1);
    run_for(scene.world, scene.dt, 10.0 - scene.dt);
    const double settled = -1.0 - scene.world.particles.x(1, 1);
    fmt::print("   {:>10}  {:>16.4f}  {:>16.4f}\n", iterations, first * 1e3, settled * 1e3);
  }
  fmt::print("\n");
}

void sweeps_against_converged() {
  fmt::print(
      "2. swinging-chain.toml: one step (h = 1/60 s) from the chain's state at t = 0.5 s, after\n"
      "   so many iterations, against the step converged by 2000 iterations: the largest\n"
      "   distance [m] of any particle; and the chain's energy after 4 s at that count\n");
  // The state at t = 0.5 s, reached by converged steps, and the converged step from it.
  const auto at_half_second = [](int iterations) {
    Scene scene = vbd_scene("swinging-chain.toml", 2000);
    run_for(scene.world, scene.dt, 0.5);
    static_cast<Vbd&>(*scene.world.integrator).iterations = iterations;
    scene.world.step(scene.dt);
    return Matrix3X(scene.world.particles.x);
  };
  const Matrix3X converged = at_half_second(2000);
  fmt::print("   {:>10}  {:>16}  {:>16}\n", "iterations", "distance [m]", "energy at 4 s [J]");
  for (int iterations : {1, 3, 10, 30, 100}) {
    const double distance = (at_half_second(iterations) - converged).colwise().norm().maxCoeff();
    Scene scene = vbd_scene("swinging-chain.toml", iterations);
    run_for(scene.world, scene.dt, 4.0);
    fmt::print("   {:>10}  {:>16.3e}  {:>16.4f}\n", iterations, distance, energy(scene.world));
  }
  fmt::print("   (the chain starts with {:.4f} J)\n\n",
             energy(vbd_scene("swinging-chain.toml", 1).world));
}

void stiff_sheet() {
  fmt::print(
      "3. stiff-sheet.toml (lesson 08's sheet: 0.34 g particles, ks = 20000 N/m) at 1/60 s for\n"
      "   4 s: the largest strain of any spring and the total energy at the end (it starts with\n"
      "   {:.4f} J)\n",
      energy(vbd_scene("stiff-sheet.toml", 1).world));
  fmt::print("   {:<34}  {:>14}  {:>12}\n", "method", "largest strain", "energy [J]");
  const auto row = [](const std::string& what, Scene scene, double seconds = 4.0) {
    try {
      run_for(scene.world, scene.dt, seconds);
      fmt::print("   {:<34}  {:>13.3f}%  {:>12.4f}\n", what, 100.0 * largest_strain(scene.world),
                 energy(scene.world));
    } catch (const SimulationError& error) {
      fmt::print("   {:<34}  stopped by the guard at step {}\n", what, error.step());
    }
  };
  Scene implicit = load_scene_file(lesson_file("stiff-sheet.toml"));
  implicit.world.integrator = make_integrator("implicit-euler");
  row("implicit Euler (linearised)", std::move(implicit));
  for (int iterations : {1, 10, 100}) {
    for (VbdInitialGuess guess : {VbdInitialGuess::inertia, VbdInitialGuess::adaptive}) {
      const std::string what =
          fmt::format("VBD, {:>3} iteration{}, {}", iterations, iterations == 1 ? " " : "s",
                      guess == VbdInitialGuess::inertia ? "inertia" : "adaptive");
      row(what, vbd_scene("stiff-sheet.toml", iterations, guess));
    }
  }
  // One sweep from the adaptive guess keeps running, and keeps gaining energy.
  row("VBD,   1 iteration , adaptive, 10 s",
      vbd_scene("stiff-sheet.toml", 1, VbdInitialGuess::adaptive), 10.0);
  fmt::print("\n");
}

void scrambled() {
  fmt::print(
      "4. scrambled-sheet.toml: 16 particles thrown at random into a 20 cm box, 10 iterations a\n"
      "   step: the worst |l - l0| / l0 of any spring as the sweeps pull the sheet flat\n");
  Scene scene = vbd_scene("scrambled-sheet.toml", 10);
  const SpringSet& s = springs_of(scene.world);
  const Particles& p = scene.world.particles;
  const auto worst = [&] {
    double w = 0.0;
    for (size_t k = 0; k < s.size(); ++k) {
      const double l = (p.x.col(s.j(k)) - p.x.col(s.i(k))).norm();
      w = std::max(w, std::abs(l - s.l0(k)) / s.l0(k));
    }
    return w;
  };
  fmt::print("   {:>8}  {:>12}\n", "t [s]", "worst strain");
  double t = 0.0;
  for (double until : {0.0, 0.1, 0.5, 1.0, 2.0, 3.0}) {
    run_for(scene.world, scene.dt, until - t);
    t = until;
    fmt::print("   {:>8.1f}  {:>11.3f}%\n", t, 100.0 * worst());
  }
}

}  // namespace

int main() {
  return clothlab::lesson::run("lesson14", [] {
    hanging_mass();
    sweeps_against_converged();
    stiff_sheet();
    scrambled();
  });
}
