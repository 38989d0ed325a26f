// step_timer.hpp: a stopwatch on the parts of a step, for `clothlab run --stats`.
//
// The step (world.cpp) is written as the lecture's, without timing. When World::timer points at
// a StepTimer, the world starts one lap of it around each part it calls (the backend's step,
// the guard, the integrator, each post-step effect) and compute_forces sums the forces with
// sum_forces below, the lecture's loop with a lap around each effect. Each lap costs two clock
// reads, once per part of a step, never once per particle; without a timer, nothing.
#pragma once

#include <chrono>
#include <vector>

#include "clothlab/core/types.hpp"

namespace clothlab {

class World;

// Wall time spent in each part of the step. Force effects and post-step effects are listed in
// the world's order.
struct StepTimes {
  std::vector<double> force_effects;      // [s] each force effect, in the sums the world made
  std::vector<double> post_step_effects;  // [s] each post-step effect the world applied
  double integrator = 0.0;                // [s] the integrator's own work, forces excluded
  double guard = 0.0;                     // [s] the guard's checks
  double backend_forces = 0.0;            // [s] force sums the backend made, every effect at once
  double backend_steps = 0.0;             // [s] what the backend took of the steps (BackendStep)
};

class StepTimer {
 public:
  StepTimes times;

  // Adds the wall time from its making to its end to *slot, and takes it from *less (a part
  // inside another: the forces the integrator asks for are not the integrator's own time). A
  // lap without a slot (no timer) does nothing.
  class Lap {
   public:
    explicit Lap(double* slot, double* less = nullptr);
    ~Lap();
    void discard() { slot_ = nullptr; }  // the part did not happen after all: count nothing
    Lap(const Lap&) = delete;
    Lap& operator=(const Lap&) = delete;

   private:
    double* slot_;
    double* less_;
    std::chrono::steady_clock::time_point start_;
  };

  // Times `world` from now on: sets World::timer, and puts a stopwatch between the world and its
  // backend, which times the steps and force sums the backend takes (the backend's type stays
  // unknown to the world, so nothing else changes). The timer must outlive the world's steps.
  void attach(World& world);

  // World::compute_forces_readable's loop, with a lap around each effect: the same f, bit for bit.
  void sum_forces(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f);
};

// A lap of `timer` (null: none) in the part `part` of its times, e.g. lap(timer,
// &StepTimes::guard), or in post-step effect k of n: lap(timer, k, n).
StepTimer::Lap lap(StepTimer* timer, double StepTimes::*part);
StepTimer::Lap lap(StepTimer* timer, size_t k, size_t n);

}  // namespace clothlab
