// aerodynamics.hpp: air pushing on the cloth's triangles.
//
// Lecture: a flat surface moving through air feels a force against its normal,
//
//   f_aero = -1/2 rho |v|^2 cd a n
//
// with rho the air density [kg/m^3], cd the drag coefficient (no unit), v [m/s] the velocity of
// the surface relative to the air, n its unit normal and a [m^2] its area as seen by the flow:
//
//   v = (v1 + v2 + v3) / 3 - v_air              mean velocity of the triangle, minus the wind
//   n* = (r2 - r1) x (r3 - r1),  n = n* / |n*|   normal, with |n*| = twice the area
//   a0 = |n*| / 2,  a = a0 (v . n) / |v|         cross-sectional area: a0 times cos(angle)
//
// Folding those together saves two square roots: |v|^2 a n = (|v| (v . n*) / (2 |n*|)) n*.
// The whole force acts on the triangle; each of its three particles takes a third. Flipping the
// triangle's winding flips n, but (v . n) n is unchanged, so the force does not depend on it.
#pragma once

#include <algorithm>
#include <vector>

#include "clothlab/core/effect.hpp"
#include "clothlab/core/triangles.hpp"
#include "clothlab/forces/wind.hpp"

namespace clothlab {

inline constexpr double kAirDensity = 1.225;  // rho of air at sea level, 15 C [kg/m^3]

// Exercise ex03.1: the total aerodynamic force [N] on the triangle (r1, r2, r3) [m] whose corners
// move at v1, v2, v3 [m/s], in air of density rho [kg/m^3] moving at v_air [m/s], with drag
// coefficient cd. Zero (never NaN) for a zero-area triangle or zero relative velocity.
Vec3 aerodynamic_force(const Vec3& r1, const Vec3& r2, const Vec3& r3, const Vec3& v1,
                       const Vec3& v2, const Vec3& v3, const Vec3& v_air, double rho, double cd);

// Exercise ex03.2: fluid drag on one particle (game-physics lecture), f = -1/2 rho |u|^2 cd a e,
// where u = v - v_air is the velocity relative to the fluid and e = u / |u| its direction;
// a [m^2] is the particle's cross-sectional area. Zero when u = 0.
Vec3 fluid_drag_force(const Vec3& v, const Vec3& v_air, double rho, double cd, double a);

class Aerodynamics final : public ForceEffect {
 public:
  Aerodynamics(std::vector<Triangle> triangles, double rho, double cd, const Vec3& v_air)
      : triangles_(std::move(triangles)), rho_(rho), cd_(cd), air_(v_air) {}
  std::string_view name() const override { return "aerodynamics"; }
  void add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                  Matrix3X& f) const override;
  // Wind may change while the simulation runs (a gust, a game's weather), or by itself in
  // time (wind.hpp).
  void set_wind(const Vec3& v_air) { air_.set_velocity(v_air); }
  const Vec3& wind() const { return air_.velocity(); }  // [m/s]
  void set_gusts(const Wind& gusts) { air_.set_gusts(gusts); }
  void set_time(double t) override { air_.set_time(t); }
  // 1/2 M |wind|^2: the kinetic energy of particles carried along at the wind's top speed.
  double energy_scale(const Particles& p, const Matrix3X& /*x*/, double /*size*/) const override {
    return air_.carried_energy(p.m.sum());
  }
  double rho() const { return rho_; }  // [kg/m^3]
  double cd() const { return cd_; }
  const std::vector<Triangle>& triangles() const { return triangles_; }
  // Drops the triangles a tear has opened (lesson 06).
  template <class Predicate>
  void remove_triangles_if(Predicate torn) {
    std::erase_if(triangles_, torn);
    version_ = next_version();
  }
  // Which change of the triangle list this effect is at: a number no other change, of any
  // effect, has had (as SpringSet::version). What keeps a view of the list compares it.
  unsigned long version() const { return version_; }

 private:
  static unsigned long next_version();

  std::vector<Triangle> triangles_;
  unsigned long version_ = next_version();
  double rho_;   // air density [kg/m^3]
  double cd_;    // drag coefficient
  AirFlow air_;  // the wind [m/s]
};

class FluidDrag final : public ForceEffect {
 public:
  FluidDrag(double rho, double cd, double area, const Vec3& v_air)
      : rho_(rho), cd_(cd), area_(area), fluid_(v_air) {}
  std::string_view name() const override { return "drag"; }
  void add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                  Matrix3X& f) const override;
  // The fluid's flow may change in time (wind.hpp), as the wind on triangles.
  void set_gusts(const Wind& gusts) { fluid_.set_gusts(gusts); }
  void set_time(double t) override { fluid_.set_time(t); }
  // 1/2 M |v_fluid|^2, as for the wind on triangles.
  double energy_scale(const Particles& p, const Matrix3X& /*x*/, double /*size*/) const override {
    return fluid_.carried_energy(p.m.sum());
  }
  double rho() const { return rho_; }  // [kg/m^3]
  double cd() const { return cd_; }
  double area() const { return area_; }                             // [m^2]
  const Vec3& fluid_velocity() const { return fluid_.velocity(); }  // [m/s]

 private:
  double rho_;     // fluid density [kg/m^3]
  double cd_;      // drag coefficient
  double area_;    // cross-sectional area of each particle [m^2]
  AirFlow fluid_;  // the fluid's velocity [m/s]
};

// Buoyancy (game-physics lecture): a particle below the fluid's surface is pushed against gravity
// with the weight of the fluid it displaces, rho V |g|. The surface is the plane at height
// `surface` measured along up = -g/|g| (y = surface for gravity along -y). Particles are points
// here, so each is either fully under (force rho V |g| up) or not at all.
class Buoyancy final : public ForceEffect {
 public:
  // g: the gravitational acceleration [m/s^2], a vector (not zero).
  Buoyancy(double rho, double volume, double surface, const Vec3& g)
      : rho_(rho),
        volume_(volume),
        surface_(surface),
        g_(g.dot(unit_direction(g))),  // |g|, where |g|^2 may underflow (g = 1e-170)
        up_(-unit_direction(g)) {}
  std::string_view name() const override { return "buoyancy"; }
  void add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                  Matrix3X& f) const override;
  // The fluid's push is conservative: U = rho V |g| (surface - h) below the surface, where
  // h = x . up is the particle's height, and 0 above: a particle held under stores the energy
  // the fluid would give it rising to the surface, so -dU/dh = rho V |g| is the lift.
  double potential_energy(const Particles& p, const Matrix3X& x) const override;
  bool external_field() const override { return true; }
  // rho V g size for every particle: what rising through the scene's size can release.
  double energy_scale(const Particles& p, const Matrix3X& /*x*/, double size) const override {
    return static_cast<double>(p.size()) * rho_ * volume_ * g_ * size;
  }
  const Vec3& up() const { return up_; }

 private:
  double rho_;      // fluid density [kg/m^3]
  double volume_;   // volume each particle displaces [m^3]
  double surface_;  // height of the fluid's surface along up [m]
  double g_;        // gravitational acceleration, magnitude [m/s^2]
  Vec3 up_;         // unit vector against gravity
};

}  // namespace clothlab
