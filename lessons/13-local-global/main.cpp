// Lesson 13: a local/global solver (fast mass-springs). Measures what the lesson's README quotes:
//   1. one mass on one spring (hanging-mass.toml): where it settles, for 1 and 10 iterations and
//      three steps, against m g / ks;
//   2. convergence as dt shrinks: a spring pendulum after 1 s against a fine RK4 reference, for
//      local/global (converged and at 10 iterations), implicit Euler and symplectic Euler;
//   3. iterations against error: how far one step of stiff-curtain.toml is from solving implicit
//      Euler's equation, after 1 to 1000 iterations, for its stiff springs and softer ones;
//   4. stability at large dt: stiff-curtain.toml and canvas-curtain.toml at 1/60 s (and 0.1 s)
//      with symplectic Euler, implicit Euler, XPBD and local/global: stretch, energy, wall time;
//   5. speed: a 128 x 128 cloth (the one `clothlab bench speed` times), in ns per spring per
//      iteration, against the force-based steps in the same run.
// ./build/lesson13 runs on the reference solutions, ./build/lesson13-student on your exercises
// (it needs those of lessons 01 to 04, 07 and 12 as well); while one is still a stub, the program
// names it and exits with code 4.
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/guard.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/local_global.hpp"
#include "clothlab/integrators/methods.hpp"
#include "clothlab/integrators/xpbd.hpp"
#include "scene/scene.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

std::unique_ptr<Integrator> local_global(int iterations) {
  auto integrator = std::make_unique<LocalGlobal>();
  integrator->iterations = iterations;
  return integrator;
}

void run(World& world, double dt, double seconds) {
  const long steps = std::lround(seconds / dt);
  for (long s = 0; s < steps; ++s)
    world.step(dt);
}

void hanging_mass() {
  fmt::print(
      "1. hanging-mass.toml: 0.1 kg on ks = 100 N/m (kd = 0.5 N s/m), after 10 s; the spring's\n"
      "   static stretch is m g / ks = {:.2f} mm\n",
      0.1 * 9.8 / 100.0 * 1e3);
  fmt::print("   {:>10}  {:>16}  {:>16}\n", "dt [s]", "1 iteration [mm]", "10 iterations [mm]");
  for (double dt : {1.0 / 30.0, 1.0 / 60.0, 1.0 / 240.0}) {
    double sag[2];
    for (int k = 0; k < 2; ++k) {
      Scene scene = load_scene_file(lesson_file("hanging-mass.toml"));
      scene.world.integrator = local_global(k == 0 ? 1 : 10);
      run(scene.world, dt, 10.0);
      sag[k] = -1.0 - scene.world.particles.x(1, 1);
    }
    fmt::print("   {:>10.5f}  {:>16.4f}  {:>16.4f}\n", dt, sag[0] * 1e3, sag[1] * 1e3);
  }
  fmt::print("\n");
}

// A 1 kg bob on a spring (ks = 1000 N/m, l0 = 1 m) from a pinned anchor, released from rest
// level with it, under gravity: where it is after 1 s.
Vec3 pendulum_after_one_second(std::unique_ptr<Integrator> integrator, double dt) {
  World world;
  world.particles.add(Vec3::Zero(), Vec3::Zero(), 1.0);
  pin(world.particles, 0);  // the anchor
  world.particles.add(Vec3(1.0, 0.0, 0.0), Vec3::Zero(), 1.0);
  SpringSet springs;
  springs.add(0, 1, 1000.0, 0.0, 1.0);
  world.force_effects.push_back(std::make_unique<SpringDampers>("springs", std::move(springs)));
  world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0.0, -9.8, 0.0)));
  world.integrator = std::move(integrator);
  run(world, dt, 1.0);
  return world.particles.x.col(1);
}

void convergence() {
  fmt::print(
      "2. A spring pendulum (1 kg, ks = 1000 N/m, released level with its anchor) after 1 s:\n"
      "   distance [m] from RK4 at dt = 1e-5 s\n");
  const Vec3 reference = pendulum_after_one_second(make_integrator("rk4"), 1e-5);
  fmt::print("   {:>10}  {:>14}  {:>14}  {:>14}  {:>14}\n", "dt [ms]", "l/g 200 it", "l/g 10 it",
             "implicit Euler", "sympl. Euler");
  for (int n : {1, 4, 16, 64}) {
    const double dt = 1.0 / 60.0 / n;
    const auto error = [&](std::unique_ptr<Integrator> integrator) {
      try {
        return fmt::format(
            "{:.6f}", (pendulum_after_one_second(std::move(integrator), dt) - reference).norm());
      } catch (const SimulationError&) {
        return std::string("blows up");
      }
    };
    fmt::print("   {:>10.4f}  {:>14}  {:>14}  {:>14}  {:>14}\n", dt * 1e3, error(local_global(200)),
               error(local_global(10)), error(make_integrator("implicit-euler")),
               error(make_integrator("symplectic-euler")));
  }
  fmt::print("\n");
}

// How far the particles are from solving implicit Euler's equation after a step from (x_n, v_n)
// with f_ext: the largest |m (x - y) / h^2 - f_springs(x) - f_ext| of any free particle [N],
// y = x_n + h v_n. For springs without dampers, as in part 3, f_springs is the springs' own force.
double residual(World& world, const Matrix3X& x_n, const Matrix3X& v_n, const Matrix3X& f_ext,
                double h) {
  const Particles& p = world.particles;
  Matrix3X f = Matrix3X::Zero(3, p.size());
  for (const auto& effect : world.force_effects) {
    if (dynamic_cast<const SpringDampers*>(effect.get())) effect->add_forces(p, p.x, p.v, f);
  }
  double worst = 0.0;
  for (Index i = 0; i < p.size(); ++i) {
    if (p.inv_m[i] == 0.0) continue;
    const Vec3 y = x_n.col(i) + h * v_n.col(i);
    const Vec3 r = p.m[i] * (p.x.col(i) - y) / (h * h) - f.col(i) - f_ext.col(i);
    worst = std::max(worst, r.norm());
  }
  return worst;
}

void iterations_against_error() {
  fmt::print(
      "3. One step (dt = 1/60 s) of stiff-curtain.toml without its dampers, from its state at\n"
      "   t = 1 s: the largest residual [N] of implicit Euler's equation of any particle (its\n"
      "   weight is 3.3e-3 N), with the scene's ks = 20000 N/m and with 100 times softer "
      "springs\n");
  const auto residual_after = [](int iterations, double softer) {
    Scene scene = load_scene_file(lesson_file("stiff-curtain.toml"));
    SpringSet& springs = springs_of(scene.world);
    for (size_t k = 0; k < springs.size(); ++k) {
      springs.set_kd(k, 0.0);
      springs.set_ks(k, springs.ks(k) / softer);
    }
    run(scene.world, scene.dt, 1.0);
    World& world = scene.world;
    // The external forces the step will take, at the state it starts from.
    Matrix3X f_ext = Matrix3X::Zero(3, world.particles.size());
    for (const auto& effect : world.force_effects) {
      if (!dynamic_cast<const SpringDampers*>(effect.get()))
        effect->add_forces(world.particles, world.particles.x, world.particles.v, f_ext);
    }
    const Matrix3X x_n = world.particles.x, v_n = world.particles.v;
    dynamic_cast<LocalGlobal&>(*world.integrator).iterations = iterations;
    world.step(scene.dt);
    return residual(world, x_n, v_n, f_ext, scene.dt);
  };
  fmt::print("   {:>10}  {:>20}  {:>20}\n", "iterations", "ks = 20000 N/m [N]", "ks = 200 N/m [N]");
  for (int iterations : {1, 3, 10, 30, 100, 300, 1000}) {
    fmt::print("   {:>10}  {:>20.3e}  {:>20.3e}\n", iterations, residual_after(iterations, 1.0),
               residual_after(iterations, 100.0));
  }
  fmt::print("\n");
}

struct Variant {
  const char* name;
  std::string method;
  int iterations;
  double dt;  // [s]
};

// The scene `file` run for 4 s with each variant: largest strain, energy and wall time.
void compare(const char* file, std::initializer_list<Variant> variants) {
  fmt::print("   {:<32}  {:>8}  {:>14}  {:>12}  {:>10}\n", "method", "dt [s]", "largest strain",
             "energy [J]", "wall [s]");
  for (const Variant& v : variants) {
    Scene scene = load_scene_file(lesson_file(file));
    scene.world.integrator = make_integrator(v.method);
    if (auto* lg = dynamic_cast<LocalGlobal*>(scene.world.integrator.get()))
      lg->iterations = v.iterations;
    if (auto* xpbd = dynamic_cast<Xpbd*>(scene.world.integrator.get())) xpbd->substeps = 20;
    const Clock::time_point start = Clock::now();
    try {
      run(scene.world, v.dt, 4.0);
    } catch (const SimulationError& error) {
      fmt::print("   {:<32}  {:>8.4f}  stopped by the guard at step {}\n", v.name, v.dt,
                 error.step());
      continue;
    }
    fmt::print("   {:<32}  {:>8.4f}  {:>13.3f}%  {:>12.4f}  {:>10.2f}\n", v.name, v.dt,
               largest_strain(scene.world) * 100.0, energy(scene.world), seconds_since(start));
  }
}

void stability() {
  const double frame = 1.0 / 60.0;  // [s]
  fmt::print(
      "4. stiff-curtain.toml (ks = 20000 N/m; symplectic Euler needs dt < 0.0955 ms) for 4 s\n");
  compare("stiff-curtain.toml", {{"symplectic Euler", "symplectic-euler", 0, frame},
                                 {"implicit Euler (linearised)", "implicit-euler", 0, frame},
                                 {"XPBD, 20 substeps", "xpbd", 1, frame},
                                 {"local/global, 1 iteration", "local-global", 1, frame},
                                 {"local/global, 10 iterations", "local-global", 10, frame},
                                 {"local/global, 100 iterations", "local-global", 100, frame},
                                 {"local/global, 10 iterations", "local-global", 10, 0.1}});
  fmt::print(
      "   canvas-curtain.toml (ten times heavier, ten times softer; symplectic Euler needs\n"
      "   dt < 0.97 ms) for 4 s\n");
  compare("canvas-curtain.toml", {{"symplectic Euler", "symplectic-euler", 0, frame},
                                  {"implicit Euler (linearised)", "implicit-euler", 0, frame},
                                  {"local/global, 10 iterations", "local-global", 10, frame},
                                  {"local/global, 100 iterations", "local-global", 100, frame},
                                  {"local/global, 10 iterations", "local-global", 10, 0.1}});
  fmt::print("\n");
}

// The 128 x 128 cloth of `clothlab bench speed`: 1 cm apart, 1 g a particle, structural and
// shear springs of 50 N/m, bending springs of 10 N/m, gravity, dt = 0.5 ms, one thread.
Scene speed_cloth(const std::string& method) {
  const int n = 128;
  return parse_scene(fmt::format("[cloth]\nrows = {0}\ncols = {0}\nspacing = 0.01\n"
                                 "origin = [0.0, 1.0, 0.0]\nmass = {1}\npins = \"top-corners\"\n"
                                 "[springs]\nks = 50.0\nkd = 0.01\n[bending]\nks = 10.0\n"
                                 "kd = 0.005\n[gravity]\n[integrator]\nmethod = \"{2}\"\n"
                                 "dt = 0.0005\nduration = 1000.0\n[engine]\nthreads = 1\n",
                                 n, 1e-3 * n * n, method),
                     "speed.toml");
}

long spring_count(World& world) {
  long springs = 0;
  for (const char* name : {"springs", "bending"}) {
    if (const SpringDampers* effect = find_spring_effect(world, name))
      springs += static_cast<long>(effect->springs().size());
  }
  return springs;
}

// The least wall time [s] of one step over `repeats` runs of `steps` steps, after one step that
// is not timed (for local/global: the factorisation).
double seconds_per_step(Scene& scene, int steps, int repeats) {
  scene.world.step(scene.dt);
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const Clock::time_point start = Clock::now();
    for (int s = 0; s < steps; ++s)
      scene.world.step(scene.dt);
    best = std::min(best, seconds_since(start) / steps);
  }
  return best;
}

void speed() {
  fmt::print(
      "5. Speed: a 128 x 128 cloth (structural, shear and bending springs, dt = 0.5 ms), one\n"
      "   thread, the best of 3 runs; ns per spring per step (and per iteration)\n");
  Scene euler = speed_cloth("symplectic-euler");
  const long springs = spring_count(euler.world);
  const double t_euler = seconds_per_step(euler, 40, 3);
  Scene implicit = speed_cloth("implicit-euler");
  const double t_implicit = seconds_per_step(implicit, 4, 3);

  Scene lg = speed_cloth("local-global");
  auto& integrator = dynamic_cast<LocalGlobal&>(*lg.world.integrator);
  const Clock::time_point start = Clock::now();
  lg.world.step(lg.dt);  // the first step factors the matrix
  const double t_first = seconds_since(start);
  fmt::print("   {} springs, {} particles\n", springs, lg.world.particles.size());
  fmt::print("   {:<34}  {:>14}  {:>18}\n", "method", "ns/spring/step", "ns/spring/iteration");
  fmt::print("   {:<34}  {:>14.2f}  {:>18}\n", "symplectic Euler (fast path)",
             t_euler / springs * 1e9, "-");
  fmt::print("   {:<34}  {:>14.2f}  {:>18}\n", "implicit Euler (linearised, CG)",
             t_implicit / springs * 1e9, "-");
  double t_10 = 0.0;
  for (int iterations : {1, 10, 20}) {
    integrator.iterations = iterations;
    const double t = seconds_per_step(lg, iterations == 1 ? 20 : 4, 3);
    if (iterations == 10) t_10 = t;
    fmt::print("   {:<34}  {:>14.2f}  {:>18.2f}\n",
               fmt::format("local/global, {} iteration{}", iterations, iterations > 1 ? "s" : ""),
               t / springs * 1e9, t / springs / iterations * 1e9);
  }
  fmt::print(
      "   the first local/global step, with the factorisation: {:.3f} s ({:.0f} steps of 10 "
      "iterations); factorisations: {}\n",
      t_first, t_first / t_10, integrator.factorizations());
}

}  // namespace

int main() {
  return lesson::run("lesson13", [&] {
    hanging_mass();
    convergence();
    iterations_against_error();
    stability();
    speed();
  });
}
