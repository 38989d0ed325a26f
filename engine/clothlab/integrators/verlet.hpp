// verlet.hpp: the two Verlet integrators of lesson 07.
//
// Verlet's method is what molecular dynamics and most game physics use: second order like the
// midpoint method, and symplectic like the lecture's Euler, so an undamped spring keeps its
// energy (up to a small wobble that does not grow) for as long as you care to run it.
//
// Velocity Verlet ("kick, drift, kick") keeps positions and velocities:
//   a  = a(x, v)
//   v* = v + dt/2 a                   half a kick
//   x' = x + dt v*                    a drift with the half-step velocity
//   a' = a(x', v + dt a)              the acceleration at the new positions
//   v' = v* + dt/2 a'                 the other half kick
// With forces that depend on positions only, a' is the next step's a and a program that knows
// this evaluates forces once per step. Dampers and drag depend on velocity, so we evaluate a'
// at a predicted velocity v + dt a (which keeps the method second order) and evaluate a afresh
// each step: two force evaluations per step, like the midpoint method.
//
// Position Verlet, as in Jakobsen's "Advanced Character Physics", keeps the previous positions
// instead of velocities:
//   x' = x + (x - x_prev) + dt^2 a(x, v),   x_prev' = x
// Velocity is implicit in x - x_prev, which is why games like it: move a particle out of a wall
// and its velocity changes with it. We still report a velocity, second-order accurate,
//   v' = (x' - x) / dt + dt/2 a,
// for outputs and for forces that depend on velocity. When something other than the integrator
// moves a particle (a collision, a pin) or dt changes, x_prev is rebuilt from the particle's
// position and velocity, x_prev = x - dt v + dt^2/2 a, which is also how the first step starts.
#pragma once

#include "clothlab/core/integrator.hpp"
#include "clothlab/core/types.hpp"

namespace clothlab {

class VelocityVerlet final : public Integrator {
 public:
  std::string_view name() const override { return "velocity-verlet"; }
  void advance(World& world, double dt) override;
  int force_evaluations_per_step() const override { return 2; }

 private:
  Matrix3X a_, a_next_, v_predicted_;
};

class PositionVerlet final : public Integrator {
 public:
  std::string_view name() const override { return "position-verlet"; }
  void advance(World& world, double dt) override;
  int force_evaluations_per_step() const override { return 1; }

 private:
  Matrix3X a_;
  Matrix3X x_prev_;           // positions one step back [m]
  Matrix3X x_left_, v_left_;  // the state this integrator left after its last step
  double dt_ = 0.0;           // the step x_prev_ belongs to [s]
};

}  // namespace clothlab
