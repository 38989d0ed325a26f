// gravitation.hpp: Newton's law of universal gravitation between every pair of particles.
//
// Lecture (game physics): F = G m1 m2 / r^2, G = 6.673e-11 N m^2/kg^2, pulling each body
// toward the other along the line between their centres. Equal and opposite on the pair, so
// the total momentum of an isolated system never changes.
#pragma once

#include "clothlab/core/effect.hpp"

namespace clothlab {

inline constexpr double kGravitationalConstant = 6.673e-11;  // G [N m^2 / kg^2]

// Exercise ex01.2: the gravitational force [N] that body 2 (at r2 [m], mass m2 [kg]) exerts on
// body 1 (at r1, mass m1), with gravitational constant G [N m^2/kg^2]. Coincident bodies
// (r1 == r2) have no direction to attract along: the force is zero, never NaN.
Vec3 gravitation_force(const Vec3& r1, double m1, const Vec3& r2, double m2, double G);

class Gravitation final : public ForceEffect {
 public:
  explicit Gravitation(double G) : G_(G) {}
  std::string_view name() const override { return "gravitation"; }
  // Visits every pair once and applies the force to both: O(n^2), meant for a few bodies.
  void add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                  Matrix3X& f) const override;
  // U = -sum over pairs of G m_i m_j / r_ij.
  double potential_energy(const Particles& p, const Matrix3X& x) const override;
  bool external_field() const override { return true; }
  double G() const { return G_; }

 private:
  double G_;  // gravitational constant [N m^2 / kg^2]
};

}  // namespace clothlab
