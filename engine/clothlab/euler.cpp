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

// The same moves, the kernel's inputs read from the fast path's copies (fast_forces.hpp), where
// component c of particle i sits at x[c nx + i]: the compiler then takes several particles at
// once with vector instructions, which the loop above, on x, y and z side by side, does not
// allow. The same operations on the same values: the same bits. The pointers are declared not
// to overlap (the outputs are the particles' own x and v, the inputs the copies), so the
// function is kept out of line.
template <class Kernel>
[[gnu::noinline, gnu::flatten]] void move_particles_from_copies(
    Index begin, Index end, double dt, Kernel kernel, const double* __restrict x, Index nx,
    const double* __restrict v, Index nv, const double* __restrict f, Index nf,
    const double* __restrict inv_m, double* __restrict x_out, double* __restrict v_out) {
  for (Index i = begin; i < end; ++i) {
    // Not const: GCC 12 does not split a const aggregate into its six doubles, and the loop
    // then goes one particle at a time through the stack (three times slower).
    PointState next =
        kernel(Vec3(x[i], x[nx + i], x[2 * nx + i]), Vec3(v[i], v[nv + i], v[2 * nv + i]),
               Vec3(f[i], f[nf + i], f[2 * nf + i]), inv_m[i], dt);
    x_out[3 * i] = next.r.x();
    x_out[3 * i + 1] = next.r.y();
    x_out[3 * i + 2] = next.r.z();
    v_out[3 * i] = next.v.x();
    v_out[3 * i + 1] = next.v.y();
    v_out[3 * i + 2] = next.v.z();
  }
}

// Both Euler methods: evaluate forces once at the current state, then move every particle
// with the one-particle kernel. `kernel` is a plain function, inlined at link time.
template <class Kernel>
void euler_advance(World& world, double dt, Kernel kernel) {
  Particles& p = world.particles;
  // Forces, then each particle moves by its own force: the loop may be split between threads,
  // and on the fast path each thread moves its particles as soon as their forces are summed,
  // reading them from the copies they were summed in.
  world.compute_forces_then(p.x, p.v, p.f, [&](Index begin, Index end, const FastScratch* copies) {
    if (!copies) {
      move_particles(p, begin, end, dt, kernel);
      return;
    }
    move_particles_from_copies(begin, end, dt, kernel, copies->x.data(), copies->x.cols(),
                               copies->v.data(), copies->v.cols(), copies->f.data(),
                               copies->f.cols(), p.inv_m.data(), p.x.data(), p.v.data());
  });
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
