#include "clothlab/euler.hpp"

#include "clothlab/world.hpp"

namespace clothlab {

namespace {

// Particles [begin, end) moved by their own forces with the one-particle kernel. `flatten` asks
// for the kernel inlined at link time whatever else the program contains: GCC otherwise weighs
// it against the kernel's other callers, and a call per particle makes the whole step about 17 %
// slower (measured when a second caller was added to clothlab).
template <class Kernel>
[[gnu::flatten]] void move_particles(Particles& p, Index begin, Index end, double dt,
                                     Kernel kernel) {
  for (Index i = begin; i < end; ++i) {
    const PointState next = kernel(p.x.col(i), p.v.col(i), p.f.col(i), p.inv_m[i], dt);
    p.x.col(i) = next.r;
    p.v.col(i) = next.v;
  }
}

// Both Euler methods: evaluate forces once at the current state, then move every particle
// with the one-particle kernel. `kernel` is a plain function, inlined at link time.
template <class Kernel>
void euler_advance(World& world, double dt, Kernel kernel) {
  Particles& p = world.particles;
  // Forces, then each particle moves by its own force: the loop may be split between threads,
  // and on the fast path each thread moves its particles as soon as their forces are summed.
  world.compute_forces_then(
      p.x, p.v, p.f, [&](Index begin, Index end) { move_particles(p, begin, end, dt, kernel); });
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
