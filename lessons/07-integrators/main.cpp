// Lesson 07: integrators and accuracy. Measures what the lesson's README quotes:
//   1. the order of every integrator: its error on spring.toml (a damped spring with an exact
//      solution) at dt = 4, 2 and 1 ms, the ratio as dt halves, and force evaluations per step;
//   2. the factor by which one step scales the energy of the undamped spring, against its
//      formula, and the energy after 1000 steps;
//   3. the largest step at which each integrator keeps the damped spring stable;
//   4. pendulum-cloth.toml with every integrator: how far the energy drifts, and the cost;
//   5. stiff-cloth.toml: symplectic Euler at the scene's 10 ms and at 0.14 ms, implicit Euler
//      at 10 ms and 2.5 ms: cost, stretch, and how far the first swing gets.
// `lesson07 SCENE.toml` prints only part 4's table, for any scene.
// ./build/lesson07 runs on the reference solutions, ./build/lesson07-student on your exercises;
// while an exercise is still a stub, the program names it and exits with code 4.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/methods.hpp"
#include "scene/scene.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

// The scene at `path`, stepping with `method`. A scene that already names the method keeps its
// own settings (the solver tolerance of implicit Euler).
Scene load_with(const std::filesystem::path& path, std::string_view method) {
  Scene scene = load_scene_file(path);
  if (scene.world.integrator->name() != method) {
    scene.world.integrator = make_integrator(method);
    if (!scene.world.integrator) throw std::runtime_error("no integrator of that name");
  }
  return scene;
}

long solver_iterations(const World& world) {
  const auto* implicit = dynamic_cast<const ImplicitEuler*>(world.integrator.get());
  return implicit ? implicit->stats().iterations : 0;
}

// --- The spring of spring.toml and its exact motion ------------------------------------------

// Particle 1 on a spring to the pinned particle 0, released at rest from a stretch.
struct Oscillator {
  double m, ks, kd, l0, stretch;  // [kg], [N/m], [N s/m], [m], [m]

  double w() const { return std::sqrt(ks / m); }                  // [rad/s]
  double zeta() const { return kd / (2.0 * std::sqrt(ks * m)); }  // damping ratio
  double wd() const { return w() * std::sqrt(1.0 - zeta() * zeta()); }

  // Underdamped, from rest: s(t) = exp(-zeta w t) (A cos(wd t) + B sin(wd t)), A = stretch,
  // B = zeta w A / wd; s is the stretch [m], ds/dt the speed along the spring [m/s].
  double s(double t) const {
    const double b = zeta() * w() * stretch / wd();
    return std::exp(-zeta() * w() * t) * (stretch * std::cos(wd() * t) + b * std::sin(wd() * t));
  }
  double ds(double t) const {
    // d/dt of s: the cos terms cancel (B wd = zeta w A), the sin terms add up to
    // -(zeta^2 w^2 + wd^2) A / wd = -(w^2 / wd) A.
    return -std::exp(-zeta() * w() * t) * (w() * w() / wd()) * stretch * std::sin(wd() * t);
  }
};

// The stretch [m] and the speed along the spring [m/s] of particle 1 in `world`.
std::pair<double, double> stretch_and_speed(const World& world, double l0) {
  const Vec3 d = world.particles.x.col(1) - world.particles.x.col(0);
  const Vec3 e = d / d.norm();
  return {d.norm() - l0, e.dot(world.particles.v.col(1) - world.particles.v.col(0))};
}

Oscillator oscillator_of(Scene& scene) {
  const SpringSet& s = springs_of(scene.world);
  const double m = scene.world.particles.m[1];
  const double l = (scene.world.particles.x.col(1) - scene.world.particles.x.col(0)).norm();
  return Oscillator{m, s.ks(0), s.kd(0), s.l0(0), l - s.l0(0)};
}

// --- 1. Order ----------------------------------------------------------------------------------

struct SpringRun {
  double error;  // distance from the exact state in phase space over the stretch
  long evaluations;
};

SpringRun run_spring(std::string_view method, double dt, double end_time) {
  Scene scene = load_with(lesson_file("spring.toml"), method);
  const Oscillator osc = oscillator_of(scene);
  const long steps = std::lround(end_time / dt);
  for (long n = 0; n < steps; ++n)
    scene.world.step(dt);
  const auto [s, ds] = stretch_and_speed(scene.world, osc.l0);
  const double t = scene.world.t;
  const double error = std::hypot(s - osc.s(t), (ds - osc.ds(t)) / osc.w()) / osc.stretch;
  return {error, scene.world.force_evaluations};
}

void orders() {
  Scene scene = load_scene_file(lesson_file("spring.toml"));
  const Oscillator osc = oscillator_of(scene);
  const double end_time = 2.0;                            // [s]
  const std::vector<double> dts = {0.004, 0.002, 0.001};  // [s]
  fmt::print(
      "1. Order: spring.toml (w = {:g} rad/s, zeta = {:g}) to t = {:g} s against the exact\n"
      "   solution; error = distance in phase space over the {:g} m stretch\n",
      osc.w(), osc.zeta(), end_time, osc.stretch);
  fmt::print("   {:>16}  {:>10}  {:>9}  {:>9}  {:>9}  {:>12}  {:>5}\n", "method", "evals/step",
             "dt = 4 ms", "2 ms", "1 ms", "ratios", "order");
  for (const std::string_view method : integrator_names()) {
    std::vector<SpringRun> runs;
    for (const double dt : dts)
      runs.push_back(run_spring(method, dt, end_time));
    const long steps = std::lround(end_time / dts.back());
    const double per_step = double(runs.back().evaluations) / double(steps);
    const double r1 = runs[0].error / runs[1].error, r2 = runs[1].error / runs[2].error;
    fmt::print("   {:>16}  {:>10g}  {:>9.2e}  {:>9.2e}  {:>9.2e}  {:>5.2f} {:>6.2f}  {:>5.2f}\n",
               method, per_step, runs[0].error, runs[1].error, runs[2].error, r1, r2,
               std::log2(r2));
  }
  fmt::print(
      "   Halving dt divides an order-p method's error by 2^p: 2 for the Euler methods,\n"
      "   4 for midpoint and Verlet, 16 for RK4. The last column is p = log2(last ratio).\n\n");
}

// --- 2. Energy factors -------------------------------------------------------------------------

// spring.toml with the spring lengthened to 1 km and the bob moved with it: the same stretch,
// the same motion. A spring pulls along its line only while the bob stays on its side of the
// anchor; a swing that an unstable method lets grow past 1 m would cross the 1 m spring's
// anchor, where the force turns round and the motion is no longer the linear one we measure.
Scene long_spring(std::string_view method, bool damped) {
  Scene scene = load_with(lesson_file("spring.toml"), method);
  SpringSet& s = springs_of(scene.world);
  Particles& p = scene.world.particles;
  const Vec3 e = (p.x.col(1) - p.x.col(0)).normalized();
  const double stretch = (p.x.col(1) - p.x.col(0)).norm() - s.l0(0);
  s.set_l0(0, 1000.0);  // [m]
  p.x.col(1) = p.x.col(0) + (s.l0(0) + stretch) * e;
  if (!damped) s.set_kd(0, 0.0);
  return scene;
}

void energy_factors() {
  const std::vector<double> ys = {0.1, 0.5, 1.0, 2.0};  // w dt
  struct Formula {
    std::string_view method, text;
    double (*factor)(double y);
  };
  const Formula formulas[] = {
      {"explicit-euler", "1 + y^2", [](double y) { return 1.0 + y * y; }},
      {"midpoint", "1 + y^4/4", [](double y) { return 1.0 + std::pow(y, 4) / 4.0; }},
      {"rk4", "1 - y^6/72 + y^8/576",
       [](double y) { return 1.0 - std::pow(y, 6) / 72.0 + std::pow(y, 8) / 576.0; }},
      {"implicit-euler", "1 / (1 + y^2)", [](double y) { return 1.0 / (1.0 + y * y); }},
  };
  Scene probe = load_scene_file(lesson_file("spring.toml"));
  const double w = oscillator_of(probe).w();
  fmt::print("2. One step of the undamped spring (kd = 0): energy after / before, y = w dt\n");
  fmt::print("   {:>16}  {:>10}  {:>10}  {:>10}  {:>10}  {}\n", "method", "y = 0.1", "y = 0.5",
             "y = 1", "y = 2", "formula");
  double worst = 0.0;  // largest relative difference from the formula
  for (const Formula& f : formulas) {
    std::string row;
    for (const double y : ys) {
      Scene scene = long_spring(f.method, false);
      const double e0 = energy(scene.world);
      scene.world.step(y / w);
      const double factor = energy(scene.world) / e0;
      worst = std::max(worst, std::abs(factor / f.factor(y) - 1.0));
      row += fmt::format("  {:>10.6f}", factor);
    }
    fmt::print("   {:>16}{}  {}\n", f.method, row, f.text);
  }
  fmt::print("   Largest relative difference from the formulas: {:.1e}\n", worst);

  const double y = 0.05;
  const long steps = 1000;  // 8 periods
  fmt::print(
      "   {} steps at y = {:g}: E / E_0 - 1 at the end, E / E_0 at its lowest and highest on\n"
      "   the way, and factor^{} - 1 where the method has a fixed factor\n",
      steps, y, steps);
  fmt::print("   {:>16}  {:>10}  {:>10}  {:>10}  {:>12}\n", "method", "end", "lowest", "highest",
             "predicted");
  for (const std::string_view method : integrator_names()) {
    Scene scene = long_spring(method, false);
    const double e0 = energy(scene.world);
    double lowest = 1.0, highest = 1.0, ratio = 1.0;
    try {
      for (long n = 0; n < steps; ++n) {
        scene.world.step(y / w);
        ratio = energy(scene.world) / e0;
        lowest = std::min(lowest, ratio);
        highest = std::max(highest, ratio);
      }
    } catch (const SimulationError&) {
      fmt::print("   {:>16}  stopped by the guard at step {}, E / E_0 = {:.6g}\n", method,
                 scene.world.steps, ratio);
      continue;
    }
    std::string predicted = "-";
    for (const Formula& f : formulas)
      if (f.method == method)
        predicted = fmt::format("{:+.3e}", std::pow(f.factor(y), steps) - 1.0);
    fmt::print("   {:>16}  {:>+10.3e}  {:>10.6f}  {:>10.6f}  {:>12}\n", method, ratio - 1.0, lowest,
               highest, predicted);
  }
  fmt::print(
      "   Symplectic Euler and the Verlets have no fixed factor: their energy swings with the\n"
      "   phase and comes back, within a band set by y, for as long as they run.\n\n");
}

// --- 3. Stability ------------------------------------------------------------------------------

// Whether the damped spring's swing dies out under steps of y / w: the highest energy over the
// second half of `steps` steps is no more than over the first half. (The energy at one step is
// no test: a symplectic method's energy swings with the phase, stable or not.)
bool stable(std::string_view method, double y, double w, long steps) {
  Scene scene = long_spring(method, true);
  double first = 0.0, second = 0.0;  // the highest energy in each half [J]
  try {
    for (long n = 1; n <= steps; ++n) {
      scene.world.step(y / w);
      double& peak = n <= steps / 2 ? first : second;
      peak = std::max(peak, energy(scene.world));
    }
  } catch (const SimulationError&) {
    return false;
  }
  return second <= first;
}

void stability_limits() {
  Scene scene = load_scene_file(lesson_file("spring.toml"));
  const Oscillator osc = oscillator_of(scene);
  const long steps = 4000;
  const double y_top = 100.0;  // search up to w dt = 100
  fmt::print(
      "3. Largest stable step on spring.toml (zeta = {:g}): the largest y = w dt at which the\n"
      "   highest energy of the last {} of {} steps is no more than of the first {} (bisection)\n",
      osc.zeta(), steps / 2, steps, steps / 2);
  fmt::print("   {:>16}  {:>8}  {:>10}\n", "method", "w dt", "dt [ms]");
  for (const std::string_view method : integrator_names()) {
    if (stable(method, y_top, osc.w(), steps)) {
      fmt::print("   {:>16}  {:>8}  {:>10}\n", method, fmt::format("> {:g}", y_top), "-");
      continue;
    }
    double lo = 0.0, hi = y_top;  // stable at lo, not at hi
    for (int k = 0; k < 30; ++k) {
      const double mid = 0.5 * (lo + hi);
      (stable(method, mid, osc.w(), steps) ? lo : hi) = mid;
    }
    // Rounded down: a limit printed must hold at exactly the value printed.
    fmt::print("   {:>16}  {:>8}  {:>10}\n", method, round_down_to(lo, 4),
               round_down_to(1e3 * lo / osc.w(), 3));
  }
  fmt::print(
      "   Without damping: explicit Euler and midpoint never (their factors exceed 1 for every\n"
      "   y), symplectic Euler and Verlet up to y = 2, RK4 up to 2 sqrt(2) = 2.83, implicit\n"
      "   Euler always.\n\n");
}

// --- 4. Energy of a scene, method by method ----------------------------------------------------

void energy_table(const std::filesystem::path& path) {
  Scene probe = load_scene_file(path);
  const double e_start = energy(probe.world);
  const long every = std::max(1L, std::lround(1.0 / (probe.output.fps * probe.dt)));
  fmt::print(
      "4. {}: {} particles, dt = {:g} s for {:g} s, E_0 = {:.6g} mJ\n"
      "   E - E_0 [mJ], sampled {:g} times a second\n",
      path.filename().string(), probe.world.particles.size(), probe.dt, probe.duration,
      1e3 * e_start, probe.output.fps);
  fmt::print("   {:>16}  {:>10}  {:>10}  {:>10}  {:>11}  {:>9}  {:>8}\n", "method", "at end",
             "lowest", "highest", "force evals", "CG iter.", "wall [s]");
  for (const std::string_view method : integrator_names()) {
    Scene scene = load_with(path, method);
    World& w = scene.world;
    const double e0 = energy(w);
    double lowest = 0.0, highest = 0.0, last = 0.0;  // [J]
    double wall = 0.0;                               // [s], stepping only
    try {
      for (long n = 1; n <= scene.step_count(); ++n) {
        const Clock::time_point start = Clock::now();
        w.step(scene.dt);
        wall += std::chrono::duration<double>(Clock::now() - start).count();
        if (n % every == 0 || n == scene.step_count()) {
          last = energy(w) - e0;
          lowest = std::min(lowest, last);
          highest = std::max(highest, last);
        }
      }
    } catch (const SimulationError&) {
      fmt::print("   {:>16}  blew up at step {} (t = {:.3f} s), E - E_0 up to {:.4g} mJ before\n",
                 method, w.steps, w.t, 1e3 * highest);
      continue;
    }
    const long iterations = solver_iterations(w);
    fmt::print("   {:>16}  {:>10.4f}  {:>10.4f}  {:>10.4f}  {:>11}  {:>9}  {:>8.3f}\n", method,
               1e3 * last, 1e3 * lowest, 1e3 * highest, w.force_evaluations,
               iterations > 0 ? fmt::format("{}", iterations) : "-", wall);
  }
  fmt::print("\n");
}

// --- 5. The stiff cloth ------------------------------------------------------------------------

void stiff_run(const char* label, std::string_view method, double dt, double tolerance) {
  Scene scene = load_with(lesson_file("stiff-cloth.toml"), method);
  World& w = scene.world;
  if (auto* implicit = dynamic_cast<ImplicitEuler*>(w.integrator.get()))
    implicit->tolerance = tolerance;
  SpringSet& s = springs_of(w);
  const Index corner = scene.cloth->at(scene.cloth->rows - 1, scene.cloth->cols - 1);
  const long steps = std::lround(scene.duration / dt);
  double strain = 0.0;                                   // largest (l - l0) / l0 of the run
  double z_low = w.particles.x(2, corner), t_low = 0.0;  // the far corner's first swing [m], [s]
  double z_back = -std::numeric_limits<double>::infinity(), t_back = 0.0;  // and its return
  double wall = 0.0;                                                       // [s], stepping only
  try {
    for (long n = 0; n < steps; ++n) {
      const Clock::time_point start = Clock::now();
      w.step(dt);
      wall += std::chrono::duration<double>(Clock::now() - start).count();
      for (size_t k = 0; k < s.size(); ++k) {
        const double l = (w.particles.x.col(s.j(k)) - w.particles.x.col(s.i(k))).norm();
        strain = std::max(strain, (l - s.l0(k)) / s.l0(k));
      }
      const double z = w.particles.x(2, corner);
      if (z < z_low) {
        z_low = z, t_low = w.t;
        z_back = -std::numeric_limits<double>::infinity();  // the return comes after the low
      } else if (z > z_back) {
        z_back = z, t_back = w.t;
      }
    }
  } catch (const SimulationError&) {
    fmt::print("   {:<26}  blew up at step {} (t = {:g} s)\n", label, w.steps, w.t);
    return;
  }
  const long iterations = solver_iterations(w);
  fmt::print(
      "   {:<26}  {:>6}  {:>8}  {:>8.2f}  {:>5.2f} %  {:>6.3f} ({:.2f})  {:>6.3f} ({:.2f})\n",
      label, steps, iterations > 0 ? fmt::format("{}", iterations) : "-", wall, 100.0 * strain,
      z_low, t_low, z_back, t_back);
}

void stiff_cloth() {
  Scene scene = load_scene_file(lesson_file("stiff-cloth.toml"));
  const auto* implicit = dynamic_cast<const ImplicitEuler*>(scene.world.integrator.get());
  const double tolerance = implicit ? implicit->tolerance : 1e-6;
  fmt::print(
      "5. stiff-cloth.toml: {} particles, ks = {:g} N/m, {:g} s, one force evaluation a step.\n"
      "   The far free corner starts at z = 0.7 m, swings out and comes back: z [m] (at t [s])\n",
      scene.world.particles.size(), springs_of(scene.world).ks(0), scene.duration);
  fmt::print("   {:<26}  {:>6}  {:>8}  {:>8}  {:>7}  {:>14}  {:>14}\n", "method, dt", "steps",
             "CG iter.", "wall [s]", "stretch", "first swing", "and back");
  stiff_run("symplectic-euler, 10 ms", "symplectic-euler", 0.01, tolerance);
  stiff_run("symplectic-euler, 0.14 ms", "symplectic-euler", 0.00014, tolerance);
  stiff_run("implicit-euler, 10 ms", "implicit-euler", 0.01, tolerance);
  stiff_run("implicit-euler, 2.5 ms", "implicit-euler", 0.0025, tolerance);
  fmt::print(
      "   stretch: the largest strain (l - l0) / l0 of any spring during the run. CG tolerance\n"
      "   {:g}, as in the scene.\n",
      tolerance);
}

}  // namespace

int main(int argc, char** argv) {
  return lesson::run("lesson07", [&] {
    if (argc > 1) {
      for (int a = 1; a < argc; ++a)
        energy_table(argv[a]);
      return;
    }
    orders();
    energy_factors();
    stability_limits();
    energy_table(lesson_file("pendulum-cloth.toml"));
    stiff_cloth();
  });
}
