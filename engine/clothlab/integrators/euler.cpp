#include "clothlab/integrators/euler.hpp"

#include "clothlab/core/world.hpp"

namespace clothlab {

namespace {

// Every particle moved by its own force with the one-particle kernel (step 3): each particle's
// new state depends on its own state and force alone.
template <class Kernel>
void move_particles(Particles& p, double dt, Kernel kernel) {
  for (Index i = 0; i < p.size(); ++i) {
    const PointState next = kernel(p.x.col(i), p.v.col(i), p.f.col(i), p.inv_m[i], dt);
    p.x.col(i) = next.r;
    p.v.col(i) = next.v;
  }
}

// Both Euler methods: forces once, at the state the step starts from (steps 1-2), then every
// particle moves by its own force (step 3).
template <class Kernel>
void euler_advance(World& world, double dt, Kernel kernel) {
  Particles& p = world.particles;
  world.compute_forces(p.x, p.v, p.f);
  move_particles(p, dt, kernel);
}

}  // namespace

// The two methods differ only in the kernel that moves one particle (lesson 01's exercises).
void ExplicitEuler::advance(World& world, double dt) {
  euler_advance(world, dt, [](const Vec3& r, const Vec3& v, const Vec3& f, double inv_m, double h) {
    return explicit_euler_step(r, v, f, inv_m, h);
  });
}

void SymplecticEuler::advance(World& world, double dt) {
  euler_advance(world, dt, [](const Vec3& r, const Vec3& v, const Vec3& f, double inv_m, double h) {
    return symplectic_euler_step(r, v, f, inv_m, h);
  });
}

}  // namespace clothlab
