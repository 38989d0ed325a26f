#include "clothlab/integrators/euler.hpp"

#include "clothlab/core/world.hpp"

namespace clothlab {

namespace {

// Every particle moved by its own force with the one-particle kernel. `flatten` asks for the
// kernel inlined at link time whatever else the program contains: GCC otherwise weighs it
// against the kernel's other callers, and a call per particle makes the step much slower.
template <class Kernel>
[[gnu::flatten]] void move_particles(Particles& p, double dt, Kernel kernel) {
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

// The kernels are passed wrapped in lambdas, not as function pointers: a lambda is a type of its
// own, so each loop is compiled for its kernel and the kernel inlined into it at link time.
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
