#include "clothlab/integrators/runge_kutta.hpp"

#include "clothlab/core/world.hpp"

namespace clothlab {

void RungeKuttaStages::resize(Index n) {
  for (auto* stage : {&x, &v, &a}) {
    for (Matrix3X& m : *stage)
      m.resize(3, n);
  }
}

AccelerationField world_acceleration(World& world) {
  return [&world](const Matrix3X& x, const Matrix3X& v, Matrix3X& a) {
    Particles& p = world.particles;
    world.compute_forces(x, v, p.f);
    // a_i = f_i / m_i for every column at once; inv_m = 0 keeps a pinned particle still.
    a.noalias() = p.f * p.inv_m.asDiagonal();
  };
}

void Midpoint::advance(World& world, double dt) {
  Particles& p = world.particles;
  stages_.resize(p.size());
  midpoint_step(p.x, p.v, dt, world_acceleration(world), stages_);
}

void RungeKutta4::advance(World& world, double dt) {
  Particles& p = world.particles;
  stages_.resize(p.size());
  rk4_step(p.x, p.v, dt, world_acceleration(world), stages_);
}

}  // namespace clothlab
