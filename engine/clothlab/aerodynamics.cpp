#include "clothlab/aerodynamics.hpp"

namespace clothlab {

void Aerodynamics::add_forces(const Particles& /*p*/, const Matrix3X& x, const Matrix3X& v,
                              Matrix3X& f) const {
  for (const Triangle& t : triangles_) {
    const Vec3 f_aero = aerodynamic_force(x.col(t[0]), x.col(t[1]), x.col(t[2]), v.col(t[0]),
                                          v.col(t[1]), v.col(t[2]), v_air_, rho_, cd_);
    const Vec3 share = f_aero / 3.0;  // each corner carries a third of the triangle
    f.col(t[0]) += share;
    f.col(t[1]) += share;
    f.col(t[2]) += share;
  }
}

// --- The fast path ---------------------------------------------------------------------------
//
// add_forces above is the lecture's loop. The fast path keeps its order, triangle by triangle,
// but takes the triangles in chunks: the corners' positions and velocities of a chunk are
// gathered into rows of their own, so that the compiler evaluates the exercise kernel (inlined
// at link time) on four triangles at once; then the chunk's shares go to the corners one
// triangle after the other, as add_forces adds them, so every particle sums the same numbers in
// the same order. A thread takes the triangles with a corner in its range and adds to those
// corners only.

namespace {

constexpr Index kTriangleChunk = 128;  // triangles per chunk: 21 KiB of gathered inputs

// share = aerodynamic_force(...) / 3 of triangles t = 0 .. count - 1, whose corners' positions
// sit in rows 0-8 of `in` (x, y, z of corner 1, then of corners 2 and 3) and velocities in rows
// 9-17, each row kTriangleChunk long; the shares go to rows 0-2 of `share`. Not inlined, so that
// its pointers can be declared not to overlap: then the compiler vectorises the loop.
[[gnu::noinline, gnu::flatten]] void aerodynamic_shares(Index count, const double* __restrict in,
                                                        double* __restrict share, const Vec3 v_air,
                                                        double rho, double cd) {
  constexpr Index n = kTriangleChunk;
  const auto corner = [&](int row, Index t) {
    return Vec3(in[row * n + t], in[(row + 1) * n + t], in[(row + 2) * n + t]);
  };
  for (Index t = 0; t < count; ++t) {
    const Vec3 f_aero = aerodynamic_force(corner(0, t), corner(3, t), corner(6, t), corner(9, t),
                                          corner(12, t), corner(15, t), v_air, rho, cd);
    const Vec3 s = f_aero / 3.0;  // each corner carries a third of the triangle
    share[t] = s.x();
    share[n + t] = s.y();
    share[2 * n + t] = s.z();
  }
}

}  // namespace

void Aerodynamics::add_forces_soa(const Particles& /*p*/, const SoA3& x, const SoA3& v, SoA3& f,
                                  Index begin, Index end) const {
  constexpr Index n = kTriangleChunk;
  const auto in_range = [&](Index i) { return begin <= i && i < end; };
  double in[18 * n];
  double share[3 * n];
  size_t chunk[n];  // which triangle each column of `in` holds
  for (size_t k = 0; k < triangles_.size();) {
    Index count = 0;
    for (; k < triangles_.size() && count < n; ++k) {
      const Triangle& t = triangles_[k];
      if (!in_range(t[0]) && !in_range(t[1]) && !in_range(t[2])) continue;
      chunk[count] = k;
      for (int c = 0; c < 3; ++c) {
        for (int d = 0; d < 3; ++d) {
          in[(3 * c + d) * n + count] = x(d, t[c]);
          in[(9 + 3 * c + d) * n + count] = v(d, t[c]);
        }
      }
      ++count;
    }
    aerodynamic_shares(count, in, share, v_air_, rho_, cd_);
    for (Index q = 0; q < count; ++q) {
      for (Index corner : triangles_[chunk[q]]) {
        if (!in_range(corner)) continue;
        for (int d = 0; d < 3; ++d)
          f(d, corner) += share[d * n + q];
      }
    }
  }
}

void FluidDrag::add_forces(const Particles& p, const Matrix3X& /*x*/, const Matrix3X& v,
                           Matrix3X& f) const {
  for (Index i = 0; i < p.size(); ++i)
    f.col(i) += fluid_drag_force(v.col(i), v_air_, rho_, cd_, area_);
}

void FluidDrag::add_forces_soa(const Particles& /*p*/, const SoA3& /*x*/, const SoA3& v, SoA3& f,
                               Index begin, Index end) const {
  for (Index i = begin; i < end; ++i)
    f.col(i) += fluid_drag_force(v.col(i), v_air_, rho_, cd_, area_);
}

void Buoyancy::add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& /*v*/,
                          Matrix3X& f) const {
  const double lift = rho_ * volume_ * g_;  // weight of the displaced fluid [N]
  for (Index i = 0; i < p.size(); ++i) {
    if (x(1, i) < surface_) f(1, i) += lift;
  }
}

double Buoyancy::potential_energy(const Particles& p, const Matrix3X& x) const {
  double energy = 0.0;
  for (Index i = 0; i < p.size(); ++i) {
    if (x(1, i) < surface_) energy -= rho_ * volume_ * g_ * (surface_ - x(1, i));
  }
  return energy;
}

}  // namespace clothlab
