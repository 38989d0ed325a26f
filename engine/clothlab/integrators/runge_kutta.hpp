// runge_kutta.hpp: the lecture's two-level (midpoint) and multipoint (Runge-Kutta 4) methods.
//
// Euler's method takes the rates of change at the start of a step and assumes they hold for the
// whole step. Runge-Kutta methods look ahead: they take trial half or full steps (stages),
// evaluate the acceleration there, and combine what they found. For the state (x, v) with
//   dx/dt = v,   dv/dt = a(x, v) = f(x, v) / m,
// the two methods of lesson 07 are:
//
//   midpoint (RK2)                       classical Runge-Kutta (RK4)
//   a1 = a(x, v)                         k1: x1 = x,            v1 = v,            a1 = a(x1, v1)
//   x2 = x + dt/2 v                      k2: x2 = x + dt/2 v1,  v2 = v + dt/2 a1,  a2 = a(x2, v2)
//   v2 = v + dt/2 a1                     k3: x3 = x + dt/2 v2,  v3 = v + dt/2 a2,  a3 = a(x3, v3)
//   a2 = a(x2, v2)                       k4: x4 = x + dt v3,    v4 = v + dt a3,    a4 = a(x4, v4)
//   x' = x + dt v2                       x' = x + dt/6 (v1 + 2 v2 + 2 v3 + v4)
//   v' = v + dt a2                       v' = v + dt/6 (a1 + 2 a2 + 2 a3 + a4)
//
// Midpoint is second order (halve dt, the error drops 4 times) for two force evaluations per
// step; RK4 is fourth order (halve dt, 16 times) for four. Whether that is worth it depends on
// the accuracy you need: `clothlab bench accuracy` measures it.
//
// The kernels work on every particle at once: x and v are Matrix3X (one column per particle),
// and Eigen evaluates an expression such as `x + 0.5 * dt * v` in one pass over memory.
#pragma once

#include <array>
#include <functional>

#include "clothlab/core/integrator.hpp"
#include "clothlab/core/types.hpp"

namespace clothlab {

// The acceleration of every particle at a trial state: accel(x, v, a) sets a = f(x, v) / m
// [m/s^2], one column per particle (0 for a pinned particle). The integrators below pass one
// that evaluates every force effect of the world; tests pass their own.
using AccelerationField = std::function<void(const Matrix3X& x, const Matrix3X& v, Matrix3X& a)>;

// The trial states of a Runge-Kutta step and the accelerations found there: stage k (0-based)
// is x[k], v[k], a[k]. Allocated once and reused every step, so a step allocates no memory.
// resize() gives every matrix n columns.
struct RungeKuttaStages {
  std::array<Matrix3X, 4> x, v, a;
  void resize(Index n);
};

// Exercise ex07.1: one midpoint (RK2) step of dt [s]: advances x [m] and v [m/s] in place, calling
// accel exactly twice. `stages` has been resized to x.cols(); use its matrices for the trial
// state and the accelerations.
void midpoint_step(Matrix3X& x, Matrix3X& v, double dt, const AccelerationField& accel,
                   RungeKuttaStages& stages);

// Exercise ex07.2: one classical Runge-Kutta (RK4) step of dt [s], calling accel exactly four
// times, with the same conventions.
void rk4_step(Matrix3X& x, Matrix3X& v, double dt, const AccelerationField& accel,
              RungeKuttaStages& stages);

// The integrators "midpoint" and "rk4": every stage evaluates the world's forces through the
// same effect pipeline as Euler does.
class Midpoint final : public Integrator {
 public:
  std::string_view name() const override { return "midpoint"; }
  void advance(World& world, double dt) override;
  int force_evaluations_per_step() const override { return 2; }

 private:
  RungeKuttaStages stages_;
};

class RungeKutta4 final : public Integrator {
 public:
  std::string_view name() const override { return "rk4"; }
  void advance(World& world, double dt) override;
  int force_evaluations_per_step() const override { return 4; }

 private:
  RungeKuttaStages stages_;
};

// An AccelerationField that evaluates every force effect of `world` and divides by the masses
// (multiplies by inv_m, so pinned particles get a = 0). The world must outlive it.
AccelerationField world_acceleration(World& world);

}  // namespace clothlab
