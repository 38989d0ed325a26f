#include "clothlab/core/step_timer.hpp"

#include "clothlab/core/backend.hpp"
#include "clothlab/core/world.hpp"

namespace clothlab {

namespace {

using Clock = std::chrono::steady_clock;

// The world's backend behind a stopwatch: each step and force sum it takes is timed, what it
// declines is not, and everything else passes through.
class TimedBackend final : public Backend {
 public:
  TimedBackend(std::unique_ptr<Backend> inner, StepTimer& timer)
      : inner_(std::move(inner)), timer_(timer) {}

  bool sum_forces(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f) override {
    StepTimer::Lap lap(&timer_.times.backend_forces, &timer_.times.integrator);
    const bool taken = inner_->sum_forces(world, x, v, f);
    if (!taken) lap.discard();
    return taken;
  }

  BackendStep step(World& world, double dt) override {
    StepTimer::Lap lap(&timer_.times.backend_steps);
    const BackendStep taken = inner_->step(world, dt);
    if (!taken.taken) lap.discard();
    return taken;
  }

  bool xpbd_project(World& world, const XpbdConstraints& constraints, const Matrix3X& x_old,
                    double h, int iterations, bool keep_lambda,
                    std::vector<double>& lambda) override {
    return inner_->xpbd_project(world, constraints, x_old, h, iterations, keep_lambda, lambda);
  }

  bool local_global_iterate(World& world, LocalGlobalSystem& system, int iterations) override {
    StepTimer::Lap lap(&timer_.times.backend_steps);
    const bool taken = inner_->local_global_iterate(world, system, iterations);
    if (!taken) lap.discard();
    return taken;
  }

  bool implicit_euler_step(World& world, double dt, double tolerance, int max_iterations,
                           VectorX& dv, LinearSolveStats& stats) override {
    StepTimer::Lap lap(&timer_.times.backend_steps);
    const bool taken = inner_->implicit_euler_step(world, dt, tolerance, max_iterations, dv, stats);
    if (!taken) lap.discard();
    return taken;
  }

 private:
  std::unique_ptr<Backend> inner_;
  StepTimer& timer_;
};

}  // namespace

StepTimer::Lap::Lap(double* slot, double* less) : slot_(slot), less_(less) {
  if (slot_) start_ = Clock::now();
}

StepTimer::Lap::~Lap() {
  if (!slot_) return;
  const double s = std::chrono::duration<double>(Clock::now() - start_).count();
  *slot_ += s;
  if (less_) *less_ -= s;
}

void StepTimer::attach(World& world) {
  world.timer = this;
  if (world.backend)
    world.backend = std::make_unique<TimedBackend>(std::move(world.backend), *this);
}

void StepTimer::sum_forces(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f) {
  f.setZero();
  ++world.force_evaluations;
  times.force_effects.resize(world.force_effects.size(), 0.0);
  for (size_t k = 0; k < world.force_effects.size(); ++k) {
    const Lap lap(&times.force_effects[k], &times.integrator);
    world.force_effects[k]->add_forces(world.particles, x, v, f);
  }
}

StepTimer::Lap lap(StepTimer* timer, double StepTimes::*part) {
  return StepTimer::Lap(timer ? &(timer->times.*part) : nullptr);
}

StepTimer::Lap lap(StepTimer* timer, size_t k, size_t n) {
  if (!timer) return StepTimer::Lap(nullptr);
  timer->times.post_step_effects.resize(n, 0.0);
  return StepTimer::Lap(&timer->times.post_step_effects[k]);
}

}  // namespace clothlab
