#include "clothlab/after_step/ground_collision.hpp"

#include <cmath>

#include "clothlab/core/world.hpp"

namespace clothlab {

namespace {

// The response the effects share: below rest_speed, an approach does not bounce (e = 0), so a
// particle resting under gravity is not relaunched by g dt every step.
PointState respond(const Vec3& r, const Vec3& v, const Vec3& n, double depth,
                   const ContactMaterial& m) {
  const double approach = -v.dot(n);  // [m/s], > 0 when moving into the surface
  const double e = approach < m.rest_speed ? 0.0 : m.e;
  return collision_response(r, v, n, depth, e, m.mu_s, m.mu_d);
}

}  // namespace

void Ground::apply(World& world, double /*dt*/) {
  collide(world.particles, 0, world.particles.size());
}

// `flatten`: the exercise's collision_response inlined at link time, as the engine's other loops
// inline their kernels. GCC otherwise calls it once per particle in contact.
[[gnu::flatten]] void Ground::collide(Particles& p, Index begin, Index end) const {
  const Vec3 up = Vec3::UnitY();
  for (Index i = begin; i < end; ++i) {
    const double depth = y0_ - p.x(1, i);
    if (!(depth > 0.0) || p.inv_m[i] == 0.0) continue;  // above the ground, or pinned
    if (model_ == Model::simple) {
      // The lecture's version: mirror the penetration, bounce, scale the sliding velocity.
      p.x(1, i) = y0_ + depth;
      p.v(1, i) = -material_.e * p.v(1, i);
      p.v(0, i) *= 1.0 - friction_;
      p.v(2, i) *= 1.0 - friction_;
      continue;
    }
    const PointState out = respond(p.x.col(i), p.v.col(i), up, depth, material_);
    p.x.col(i) = out.r;
    p.v.col(i) = out.v;
    p.x(1, i) = std::max(p.x(1, i), y0_);  // exactly on the ground, whatever the rounding
  }
}

void Sphere::apply(World& world, double /*dt*/) {
  collide(world.particles, 0, world.particles.size());
}

[[gnu::flatten]] void Sphere::collide(Particles& p, Index begin, Index end) const {
  for (Index i = begin; i < end; ++i) {
    const Vec3 d = p.x.col(i) - centre_;
    const double distance = d.norm();
    if (!(distance < radius_) || p.inv_m[i] == 0.0) continue;
    // The outward normal; a particle exactly at the centre is pushed out upward.
    const Vec3 n = distance > 0.0 ? Vec3(d / distance) : Vec3::UnitY();
    const PointState out = respond(p.x.col(i), p.v.col(i), n, radius_ - distance, material_);
    p.x.col(i) = out.r;
    p.v.col(i) = out.v;
  }
}

}  // namespace clothlab
