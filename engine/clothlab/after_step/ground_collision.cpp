#include "clothlab/after_step/ground_collision.hpp"

#include <algorithm>
#include <cmath>

#include "clothlab/core/world.hpp"

namespace clothlab {

namespace {

// The response the effects share. Only an arrival bounces. A particle that began the step on
// the surface, not coming at it faster than rest_speed beyond what this step's own forces added,
// is in resting contact: pushed in by this step's forces, with nothing to bounce from. An
// approach slower than rest_speed does not bounce either. For both, e = 0: so a particle resting
// under gravity is not relaunched by g dt every step, however large dt is.
PointState respond(const Vec3& r, const Vec3& v, const Vec3& n, double depth,
                   const ContactMaterial& m, bool began_touching, const Vec3& v0) {
  const double approach = -v.dot(n);  // [m/s], > 0 when moving into the surface
  const double approach0 = -v0.dot(n);
  const bool resting =
      began_touching && approach0 <= m.rest_speed + std::max(0.0, approach - approach0);
  const double e = resting || approach < m.rest_speed ? 0.0 : m.e;
  return collision_response(r, v, n, depth, e, m.mu_s, m.mu_d);
}

// True when the response left no tangential velocity: static friction held the particle (up to
// the rounding of v - (v . n) n). A particle that slides keeps some; one that arrived without
// any is held too.
bool held(const Vec3& v_before, const Vec3& v_after, const Vec3& n) {
  const double before = (v_before - v_before.dot(n) * n).norm();
  const double after = (v_after - v_after.dot(n) * n).norm();
  return after <= 1e-9 * (before + v_after.norm());
}

// Where the step's straight path from x0 (height0 above the surface, or inside if negative) to x1
// (depth1 > 0 inside) met the surface: x0 itself for a particle that began on or in it.
Vec3 where_it_met(const Vec3& x0, const Vec3& x1, double height0, double depth1) {
  const double s = height0 > 0.0 ? height0 / (height0 + depth1) : 0.0;
  return x0 + s * (x1 - x0);
}

// Whether a particle that began the step at x0, height0 [m] above the surface, was touching it:
// on it up to the rounding of its coordinates, or inside.
bool touching(double height0, const Vec3& x0) {
  return height0 <= 1e-12 * (1.0 + x0.lpNorm<Eigen::Infinity>());
}

// The loop of Ground::collide and Sphere::collide: each free particle of [begin, end) through
// surface.contact (put back out if it is inside), with the state the step began with when
// `start` knows it.
template <class Surface>
void collide_each(const Surface& surface, const StepStart& start, Particles& p, Index begin,
                  Index end) {
  const bool known = start.known(p);
  for (Index i = begin; i < end; ++i) {
    if (p.inv_m[i] == 0.0) continue;  // pinned
    Vec3 x = p.x.col(i), v = p.v.col(i);
    if (!surface.contact(x, v, known, known ? start.x(i) : x, known ? start.v(i) : v)) continue;
    p.x.col(i) = x;
    p.v.col(i) = v;
  }
}

}  // namespace

void StepStart::record(const World& world) {
  x_ = world.particles.x;
  v_ = world.particles.v;
}

void StepStart::resize(Index n) {
  x_.resize(3, n);
  v_.resize(3, n);
}

void StepStart::record(const Matrix3X& x, const Matrix3X& v, Index begin, Index end) {
  x_.middleCols(begin, end - begin) = x.middleCols(begin, end - begin);
  v_.middleCols(begin, end - begin) = v.middleCols(begin, end - begin);
}

void Ground::apply(World& world, const StepTime& /*time*/) {
  collide(world.particles, 0, world.particles.size());
}

// Each free particle the step left below the ground is put back on it, and its velocity answers
// the contact: the exercise's collision_response (ex05.1) for the Coulomb model, the lecture's
// mirror for the simple one.
void Ground::collide(Particles& p, Index begin, Index end) const {
  collide_each(*this, start_, p, begin, end);
}

bool Ground::contact(Vec3& x, Vec3& v, bool known, const Vec3& x0, const Vec3& v0) const {
  const double depth = y0_ - x.y();
  if (!(depth > 0.0)) return false;  // above the ground
  if (model_ == Model::simple) {
    // The lecture's version: mirror the penetration, bounce, scale the sliding velocity.
    x.y() = y0_ + depth;
    v.y() = -material_.e * v.y();
    v.x() *= 1.0 - friction_;
    v.z() *= 1.0 - friction_;
    return true;
  }
  const Vec3 up = Vec3::UnitY();
  const Vec3 x1 = x;
  const Vec3 v1 = v;
  const double height0 = known ? x0.y() - y0_ : 1.0;  // where the step began
  const PointState out =
      respond(x1, v1, up, depth, material_, known && touching(height0, x0), known ? v0 : v1);
  x = out.r;
  v = out.v;
  if (known && held(v1, out.v, up)) {
    const Vec3 met = where_it_met(x0, x1, height0, depth);
    x.x() = met.x();
    x.z() = met.z();
  }
  x.y() = std::max(x.y(), y0_);  // exactly on the ground, whatever the rounding
  return true;
}

void Sphere::apply(World& world, const StepTime& /*time*/) {
  collide(world.particles, 0, world.particles.size());
}

void Sphere::collide(Particles& p, Index begin, Index end) const {
  collide_each(*this, start_, p, begin, end);
}

bool Sphere::contact(Vec3& x, Vec3& v, bool known, const Vec3& x0, const Vec3& v0) const {
  const Vec3 d = x - centre_;
  const double distance = d.norm();
  if (!(distance < radius_)) return false;
  // The outward normal; a particle exactly at the centre is pushed out upward.
  const Vec3 n = distance > 0.0 ? Vec3(d / distance) : Vec3::UnitY();
  const Vec3 x1 = x;
  const Vec3 v1 = v;
  const double height0 = known ? (x0 - centre_).norm() - radius_ : 1.0;
  const PointState out = respond(x1, v1, n, radius_ - distance, material_,
                                 known && touching(height0, x0), known ? v0 : v1);
  x = out.r;
  v = out.v;
  if (known && held(v1, out.v, n)) {
    const Vec3 met = where_it_met(x0, x1, height0, radius_ - distance);
    const Vec3 from_centre = met - centre_;
    const double r = from_centre.norm();
    if (r > 0.0) x = centre_ + radius_ / r * from_centre;
  }
  return true;
}

void Plane::apply(World& world, const StepTime& /*time*/) {
  collide(world.particles, 0, world.particles.size());
}

void Plane::collide(Particles& p, Index begin, Index end) const {
  for (Index i = begin; i < end; ++i) {
    const Vec3 x1 = p.x.col(i);
    const double depth = -(x1 - point_).dot(normal_);
    if (!(depth > 0.0) || p.inv_m[i] == 0.0) continue;
    const Vec3 v1 = p.v.col(i);
    const bool known = start_.known(p);
    const double height0 = known ? (start_.x(i) - point_).dot(normal_) : 1.0;
    const PointState out =
        respond(x1, v1, normal_, depth, material_, known && touching(height0, start_.x(i)),
                known ? start_.v(i) : v1);
    Vec3 x = out.r;
    p.v.col(i) = out.v;
    if (known && held(v1, out.v, normal_)) x = where_it_met(start_.x(i), x1, height0, depth);
    // On the plane, whatever the rounding: a point it left below is lifted onto it.
    const double below = -(x - point_).dot(normal_);
    if (below > 0.0) x += below * normal_;
    p.x.col(i) = x;
  }
}

}  // namespace clothlab
