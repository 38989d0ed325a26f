// gravity.hpp: uniform gravity near the Earth's surface.
//
// Lecture: f_gravity = m g, with g = (0, -9.8, 0) m/s^2. Every particle falls with the same
// acceleration whatever its mass, because the force grows with the mass it has to move.
#pragma once

#include "clothlab/core/effect.hpp"

namespace clothlab {

// Exercise ex01.1: the force [N] uniform gravity g [m/s^2] exerts on a particle of mass m [kg].
// Defined in exercises/01_particles_and_euler.cpp (yours) and solutions/ (the reference).
Vec3 gravity_force(double m, const Vec3& g);

class UniformGravity final : public ForceEffect {
 public:
  explicit UniformGravity(const Vec3& g) : g_(g) {}
  std::string_view name() const override { return "gravity"; }
  void add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                  Matrix3X& f) const override;
  // U = -sum m g.x: lifting a particle against g stores energy.
  double potential_energy(const Particles& p, const Matrix3X& x) const override;
  // M |g| size: what falling the scene's size releases (U itself depends on the origin).
  double energy_scale(const Particles& p, const Matrix3X& x, double size) const override;
  bool external_field() const override { return true; }
  const Vec3& g() const { return g_; }

 private:
  Vec3 g_;  // gravitational acceleration [m/s^2]
};

}  // namespace clothlab
