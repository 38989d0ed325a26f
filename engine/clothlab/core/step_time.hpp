// step_time.hpp: the time a post-step effect is applied with, as one record.
//
// A method may split a step of dt into substeps (XPBD, lesson 12: `substeps` of h = dt / substeps,
// Integrator::substeps_per_step). A contact with a fixed solid (PostStepEffect::each_substep) then
// applies after every substep, the integrator applying substeps 0 to n-2 and World::step the last;
// every other post-step effect applies once, after the whole step. Either way the effect is told,
// in one record, which span of time it closes, as Box2D's step context (b2StepContext: dt, h,
// subStepCount) tells its solvers:
//
//   the step             [t, t + dt]
//   substep k of n       [t + k h, t + (k + 1) h],   h = dt / n,   the last ending at t + dt
//
// A step taken whole is substep 0 of 1, with h = dt. An effect that changes with time uses h for
// the span it closes (a plastic flow over h, a velocity dr / h) and end() for when it closes (a
// moving pin's place then), so that it is right on a substep as on a step.
#pragma once

namespace clothlab {

struct StepTime {
  double t = 0.0;    // when the step starts [s] (World::t during the step)
  double dt = 0.0;   // the whole step [s]
  double h = 0.0;    // the span this application closes [s]: the substep, or dt for a whole step
  int substep = 0;   // which substep it closes, 0 to substeps - 1
  int substeps = 1;  // how many the step is split into

  // The whole step of dt from t: substep 0 of 1.
  static StepTime whole(double t, double dt) { return {t, dt, dt, 0, 1}; }

  // Substep k of n of the step of dt from t, h = dt / n (as the integrator computes it).
  static StepTime of_substep(double t, double dt, int k, int n) { return {t, dt, dt / n, k, n}; }

  bool last() const { return substep + 1 == substeps; }  // closes the whole step as well

  // When the span closes [s]: t + (k + 1) h, and exactly t + dt on the last substep.
  double end() const { return last() ? t + dt : t + (substep + 1) * h; }
};

}  // namespace clothlab
