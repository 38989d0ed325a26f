#include "clothlab/forces/aerodynamics.hpp"

#include <atomic>

namespace clothlab {

unsigned long Aerodynamics::next_version() {
  static std::atomic<unsigned long> changes{0};
  return ++changes;
}

void Aerodynamics::add_forces(const Particles& /*p*/, const Matrix3X& x, const Matrix3X& v,
                              Matrix3X& f) const {
  for (const Triangle& t : triangles_) {
    const Vec3 f_aero = aerodynamic_force(x.col(t[0]), x.col(t[1]), x.col(t[2]), v.col(t[0]),
                                          v.col(t[1]), v.col(t[2]), air_.velocity(), rho_, cd_);
    const Vec3 share = f_aero / 3.0;  // each corner carries a third of the triangle
    f.col(t[0]) += share;
    f.col(t[1]) += share;
    f.col(t[2]) += share;
  }
}

void FluidDrag::add_forces(const Particles& p, const Matrix3X& /*x*/, const Matrix3X& v,
                           Matrix3X& f) const {
  for (Index i = 0; i < p.size(); ++i)
    f.col(i) += fluid_drag_force(v.col(i), fluid_.velocity(), rho_, cd_, area_);
}

void Buoyancy::add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& /*v*/,
                          Matrix3X& f) const {
  const Vec3 lift = rho_ * volume_ * g_ * up_;  // weight of the displaced fluid, upward [N]
  for (Index i = 0; i < p.size(); ++i) {
    if (x.col(i).dot(up_) < surface_) f.col(i) += lift;
  }
}

double Buoyancy::potential_energy(const Particles& p, const Matrix3X& x) const {
  double energy = 0.0;
  for (Index i = 0; i < p.size(); ++i) {
    const double height = x.col(i).dot(up_);
    if (height < surface_) energy += rho_ * volume_ * g_ * (surface_ - height);
  }
  return energy;
}

}  // namespace clothlab
