// ground_collision.hpp: particles meeting the ground and solid spheres (lesson 05).
//
// Detection and response are separate. Detection (here, in the engine) finds a particle that
// has ended a step inside a solid: below the ground plane y = y0, or inside a sphere. It knows
// how deep the particle is and the surface's outward unit normal n there. Response (exercise
// 5.1) puts the particle back on the surface and changes its velocity:
//
//   normal part      v_n = (v . n) n; if the particle is moving in (v . n < 0) it bounces back
//                    with restitution e: v_n' = -e v_n  (e = 1 elastic, e = 0 no bounce)
//   tangential part  v_t = v - v_n, resisted by Coulomb friction. The bounce is an impulse
//                    j = (1 + e) |v . n| per unit mass; friction can take at most mu j from v_t:
//                    static: if |v_t| <= mu_s j the particle sticks, v_t' = 0;
//                    dynamic: otherwise it slides on, v_t' = v_t (1 - mu_d j / |v_t|).
//
// Friction only ever slows the sliding, never reverses it, so it cannot add energy.
//
// Sticking holds positions too. The step has already carried the particle along the surface
// before the contact is found; a particle that static friction holds is put back where its path
// met the surface (where it stood, for a particle resting on it), so a block that should rest on
// a slope rests, at any dt and with any integrator, instead of creeping by g_t dt^2 a step. The
// contact effects record the positions each step starts from for this (before_step).
//
// The
// lecture's simpler version (reflect, v.y = -e v.y, v.x and v.z scaled by 1 - friction) is kept
// beside it as model = "simple", so a lesson can compare the two.
#pragma once

#include "clothlab/core/effect.hpp"

namespace clothlab {

// Exercise ex05.1: the response of a particle at r [m] with velocity v [m/s], found `depth` [m]
// inside a solid whose outward unit normal at the contact is n: the particle is moved out by
// depth along n, and its velocity is changed as above with restitution e and friction
// coefficients mu_s (static) and mu_d (dynamic).
PointState collision_response(const Vec3& r, const Vec3& v, const Vec3& n, double depth, double e,
                              double mu_s, double mu_d);

// The contact constants of a surface.
struct ContactMaterial {
  double e = 0.3;           // restitution, 0 to 1
  double mu_s = 0.5;        // static friction coefficient
  double mu_d = 0.4;        // dynamic friction coefficient (<= mu_s)
  double rest_speed = 0.1;  // [m/s] slower approaches do not bounce: resting contact stays calm
};

// The positions and velocities the particles had when the step began, which a contact effect
// records: to tell a particle resting on the surface from one arriving at it, and to put a
// particle static friction holds back where its path met the surface.
class StepStart {
 public:
  void record(const World& world);
  // The same in parts, for a backend whose threads each record their own particles (the fast
  // engine's pass, before anything moves): resize for n particles, then record particles
  // [begin, end) of x and v.
  void resize(Index n);
  void record(const Matrix3X& x, const Matrix3X& v, Index begin, Index end);
  // Where particle i was when the step began; false when it is not known (the effect was applied
  // outside World::step, or the particles changed in number since).
  bool known(const Particles& p) const { return x_.cols() == p.size(); }
  Vec3 x(Index i) const { return x_.col(i); }
  Vec3 v(Index i) const { return v_.col(i); }

 private:
  Matrix3X x_, v_;
};

// The ground plane y = y0, solid below.
class Ground final : public PostStepEffect {
 public:
  enum class Model { coulomb, simple };
  Ground(double y0, const ContactMaterial& material, Model model, double friction)
      : y0_(y0), material_(material), model_(model), friction_(friction) {}
  std::string_view name() const override { return "ground"; }
  void before_step(const World& world) override { start_.record(world); }
  bool each_substep() const override { return true; }
  void apply(World& world, const StepTime& time) override;
  // apply's loop on particles [begin, end) only: each particle is pushed out from its own state
  // alone, so ranges may be taken apart (and by different threads at once).
  void collide(Particles& p, Index begin, Index end) const;
  // collide's response for one free particle: x and v, where the step left it, put back on the
  // ground and answering the contact if it is below; x0 and v0, its state when the step began
  // (used if `known`). Returns whether it was below. A backend that keeps the state in a layout
  // of its own (a run of steps, fast/resident.hpp) calls it with the same values.
  bool contact(Vec3& x, Vec3& v, bool known, const Vec3& x0, const Vec3& v0) const;
  // What before_step records, for a backend that records it itself (World::record_step_start).
  StepStart& step_start() { return start_; }
  double y0() const { return y0_; }

 private:
  double y0_;  // height of the ground [m]
  ContactMaterial material_;
  Model model_;
  double friction_;  // the simple model's tangential loss per contact, 0 to 1
  StepStart start_;
};

// A plane through `point` with outward unit normal `normal`, solid on the other side: a ramp.
// The ground is the plane through (0, y0, 0) with normal +y.
class Plane final : public PostStepEffect {
 public:
  // `normal` need not be of unit length; it must not be zero.
  Plane(const Vec3& point, const Vec3& normal, const ContactMaterial& material)
      : point_(point), normal_(unit_direction(normal)), material_(material) {}
  std::string_view name() const override { return "plane"; }
  void before_step(const World& world) override { start_.record(world); }
  bool each_substep() const override { return true; }
  void apply(World& world, const StepTime& time) override;
  void collide(Particles& p, Index begin, Index end) const;
  const Vec3& point() const { return point_; }
  const Vec3& normal() const { return normal_; }

 private:
  Vec3 point_;   // [m]
  Vec3 normal_;  // outward unit normal
  ContactMaterial material_;
  StepStart start_;
};

// A solid sphere the cloth can drape over.
class Sphere final : public PostStepEffect {
 public:
  Sphere(const Vec3& centre, double radius, const ContactMaterial& material)
      : centre_(centre), radius_(radius), material_(material) {}
  std::string_view name() const override { return "sphere"; }
  void before_step(const World& world) override { start_.record(world); }
  bool each_substep() const override { return true; }
  void apply(World& world, const StepTime& time) override;
  // apply's loop on particles [begin, end) only (as Ground::collide).
  void collide(Particles& p, Index begin, Index end) const;
  // collide's response for one free particle, as Ground::contact: whether it was inside.
  bool contact(Vec3& x, Vec3& v, bool known, const Vec3& x0, const Vec3& v0) const;
  // What before_step records, for a backend that records it itself (World::record_step_start).
  StepStart& step_start() { return start_; }
  const Vec3& centre() const { return centre_; }
  double radius() const { return radius_; }

 private:
  Vec3 centre_;    // [m]
  double radius_;  // [m]
  ContactMaterial material_;
  StepStart start_;
};

}  // namespace clothlab
