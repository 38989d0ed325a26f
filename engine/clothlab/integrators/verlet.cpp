#include "clothlab/integrators/verlet.hpp"

#include "clothlab/core/world.hpp"
#include "clothlab/integrators/runge_kutta.hpp"

namespace clothlab {

void VelocityVerlet::advance(World& world, double dt) {
  Particles& p = world.particles;
  const AccelerationField accel = world_acceleration(world);
  a_.resize(3, p.size());
  a_next_.resize(3, p.size());
  accel(p.x, p.v, a_);
  v_predicted_ = p.v + dt * a_;  // v + dt a, where the second acceleration is evaluated
  p.v += (0.5 * dt) * a_;        // the first half kick: v*
  p.x += dt * p.v;               // the drift
  accel(p.x, v_predicted_, a_next_);
  p.v += (0.5 * dt) * a_next_;  // the second half kick
}

void PositionVerlet::advance(World& world, double dt) {
  Particles& p = world.particles;
  const Index n = p.size();
  a_.resize(3, n);
  world_acceleration(world)(p.x, p.v, a_);

  // Rebuild x_prev for every particle the integrator did not leave where it is now.
  const bool restart = x_prev_.cols() != n || dt != dt_;
  if (restart) x_prev_.resize(3, n);
  for (Index i = 0; i < n; ++i) {
    if (restart || p.x.col(i) != x_left_.col(i) || p.v.col(i) != v_left_.col(i))
      x_prev_.col(i) = p.x.col(i) - dt * p.v.col(i) + (0.5 * dt * dt) * a_.col(i);
  }
  dt_ = dt;

  // x' = 2x - x_prev + dt^2 a, then x_prev' = x. x_left_ holds x' while x_prev_ takes x.
  x_left_ = 2.0 * p.x - x_prev_ + (dt * dt) * a_;
  x_prev_.swap(p.x);  // x_prev_ now holds x, p.x the stale x_prev (overwritten next)
  p.x = x_left_;
  p.v = (p.x - x_prev_) / dt + (0.5 * dt) * a_;
  v_left_ = p.v;
}

}  // namespace clothlab
