#include "analysis/accuracy.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "analysis/stability.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/methods.hpp"
#include "scene/scene.hpp"

namespace clothlab {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The integrator called `name`, or an error naming the ones there are.
std::unique_ptr<Integrator> integrator_called(const std::string& name) {
  std::unique_ptr<Integrator> integrator = make_integrator(name);
  if (!integrator) throw std::invalid_argument(fmt::format("no integrator called '{}'", name));
  return integrator;
}

long whole_steps(double end_time, double dt) {
  return std::lround(end_time / dt);
}

}  // namespace

// --- The damped oscillator ---------------------------------------------------------------

DampedOscillatorProblem::DampedOscillatorProblem(double mass, double ks, double zeta,
                                                 double end_time)
    : mass_(mass),
      ks_(ks),
      kd_(2.0 * zeta * std::sqrt(ks * mass)),
      zeta_(zeta),
      omega_(std::sqrt(ks / mass)),
      end_time_(end_time) {
  if (!(zeta >= 0.0 && zeta < 1.0)) {
    throw std::invalid_argument("the damped oscillator needs 0 <= zeta < 1 (underdamped)");
  }
}

World DampedOscillatorProblem::make_world(const std::string& integrator) const {
  World world;
  world.particles.add(Vec3::Zero(), Vec3::Zero(), mass_);  // the anchor, pinned below
  world.particles.inv_m[0] = 0.0;
  world.particles.add(Vec3(1.0 + kStretch, 0.0, 0.0), Vec3::Zero(), mass_);
  SpringSet spring;
  spring.add(0, 1, ks_, kd_, 1.0);
  world.force_effects.push_back(std::make_unique<SpringDampers>("springs", std::move(spring)));
  world.integrator = integrator_called(integrator);
  // The linear solves of implicit Euler must not limit its accuracy here.
  if (auto* implicit = dynamic_cast<ImplicitEuler*>(world.integrator.get())) {
    implicit->tolerance = 1e-13;
    implicit->max_iterations = 100;
  }
  return world;
}

// Underdamped: x(t) = exp(-zeta w t) (A cos(wd t) + B sin(wd t)), wd = w sqrt(1 - zeta^2),
// with A = x0 and B = (v0 + zeta w x0) / wd; here v0 = 0.
double DampedOscillatorProblem::exact_x(double t) const {
  const double wd = omega_ * std::sqrt(1.0 - zeta_ * zeta_);
  const double a = kStretch, b = zeta_ * omega_ * kStretch / wd;
  return std::exp(-zeta_ * omega_ * t) * (a * std::cos(wd * t) + b * std::sin(wd * t));
}

double DampedOscillatorProblem::exact_v(double t) const {
  const double wd = omega_ * std::sqrt(1.0 - zeta_ * zeta_);
  const double a = kStretch, b = zeta_ * omega_ * kStretch / wd;
  const double decay = std::exp(-zeta_ * omega_ * t);
  return decay * ((b * wd - zeta_ * omega_ * a) * std::cos(wd * t) -
                  (a * wd + zeta_ * omega_ * b) * std::sin(wd * t));
}

// The distance in phase space, sqrt(|dx|^2 + |dv / w|^2), over the initial stretch.
double DampedOscillatorProblem::error(const World& world) const {
  const Vec3 x_exact(1.0 + exact_x(world.t), 0.0, 0.0);
  const Vec3 v_exact(exact_v(world.t), 0.0, 0.0);
  const Vec3 dx = world.particles.x.col(1) - x_exact;
  const Vec3 dv = (world.particles.v.col(1) - v_exact) / omega_;
  return std::sqrt(dx.squaredNorm() + dv.squaredNorm()) / kStretch;
}

bool DampedOscillatorProblem::stable(const World& world, double error) const {
  // The oscillator is linear, so stability is decided exactly by the integrator's step matrix
  // (stability.hpp, checked against the engine step for step in the tests): no eigenvalue
  // beyond 1 in modulus. An energy test would misjudge symplectic methods without damping,
  // whose energy wobbles above its start without growing.
  const double rho = spectral_radius(oscillator_step_matrix(
      world.integrator->name(), world.t / static_cast<double>(world.steps), omega_, kd_ / mass_));
  return std::isfinite(error) && rho <= 1.0 + 1e-12;
}

std::string DampedOscillatorProblem::description() const {
  return fmt::format(
      "a {} kg particle on a spring (ks = {} N/m, kd = {:.3g} N s/m: w = {:.3g} rad/s, zeta = "
      "{}) released from a 0.5 m stretch, to t = {} s; error against the exact solution in "
      "phase space, relative to the stretch",
      mass_, ks_, kd_, omega_, zeta_, end_time_);
}

// --- A scene ------------------------------------------------------------------------------

SceneProblem::SceneProblem(std::string path, double end_time, double reference_dt)
    : path_(std::move(path)), end_time_(end_time), reference_dt_(reference_dt) {
  Scene scene = load_scene_file(path_);
  scene_dt_ = scene.dt;
  const Matrix3X& x0 = scene.world.particles.x;
  const double diagonal = (x0.rowwise().maxCoeff() - x0.rowwise().minCoeff()).norm();
  size_ = diagonal > 0.0 ? diagonal : 1.0;
  for (const auto& effect : scene.world.post_step_effects) {
    if (!post_step_names_.empty()) post_step_names_ += ", ";
    post_step_names_ += effect->name();
  }
  // The reference: RK4 at reference_dt, once.
  World reference = make_world("rk4");
  const long steps = whole_steps(end_time_, reference_dt_);
  for (long s = 0; s < steps; ++s)
    reference.step(reference_dt_);
  reference_x_ = reference.particles.x;
}

World SceneProblem::make_world(const std::string& integrator) const {
  Scene scene = load_scene_file(path_);
  // Keep the scene's solver settings when it names the implicit method itself.
  if (scene.world.integrator->name() != integrator) {
    scene.world.integrator = integrator_called(integrator);
  }
  return std::move(scene.world);
}

double SceneProblem::error(const World& world) const {
  const Matrix3X& x = world.particles.x;
  if (x.cols() != reference_x_.cols()) return kNaN;
  const double rms = std::sqrt((x - reference_x_).colwise().squaredNorm().mean());
  return rms / size_;
}

bool SceneProblem::stable(const World& /*world*/, double error) const {
  return std::isfinite(error) && error < 1.0;
}

std::string SceneProblem::description() const {
  std::string text = fmt::format(
      "{} to t = {} s; error: the particles' RMS distance from an RK4 run at dt = {:.3g} s, "
      "relative to the scene's size ({:.3g} m)",
      path_, end_time_, reference_dt_, size_);
  if (!post_step_names_.empty()) {
    text += fmt::format(
        ". Post-step effects ({}) act once per step whatever the integrator, which caps every "
        "method's order near 1",
        post_step_names_);
  }
  return text;
}

// --- The study ----------------------------------------------------------------------------

std::vector<AccuracyRun> run_accuracy_study(
    const AccuracyProblem& problem, const std::vector<std::string>& integrators,
    const std::vector<double>& dts, double min_seconds,
    const std::function<void(const AccuracyRun&)>& progress) {
  using Clock = std::chrono::steady_clock;
  std::vector<AccuracyRun> runs;
  for (const std::string& integrator : integrators) {
    for (const double dt : dts) {
      AccuracyRun run;
      run.integrator = integrator;
      run.dt = dt;
      run.steps = whole_steps(problem.end_time(), dt);
      run.wall_per_sim = std::numeric_limits<double>::infinity();
      double total = 0.0;
      for (int repeat = 0; repeat < 1000 && (repeat == 0 || total < min_seconds); ++repeat) {
        World world = problem.make_world(integrator);
        const Clock::time_point start = Clock::now();
        try {
          for (long s = 0; s < run.steps; ++s)
            world.step(dt);
        } catch (const SimulationError& e) {
          run.stopped = e.what();
        }
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        total += seconds;
        run.wall_per_sim = std::min(run.wall_per_sim, seconds / problem.end_time());
        if (repeat == 0) {
          run.evals_per_sim = static_cast<double>(world.force_evaluations) / problem.end_time();
          run.error = run.stopped.empty() ? problem.error(world) : kNaN;
          run.stable = run.stopped.empty() && problem.stable(world, run.error);
        }
        if (!run.stopped.empty()) break;  // a run that blew up is not timed again
      }
      if (progress) progress(run);
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

double observed_order(const AccuracyRun& coarse, const AccuracyRun& fine) {
  return std::log(coarse.error / fine.error) / std::log(coarse.dt / fine.dt);
}

}  // namespace clothlab
