// euler.hpp: the two Euler integrators of lesson 01.
//
// Newton's second law gives the acceleration a = f / m. Euler's method then steps forward by
// dt assuming the rates of change stay what they are at the start of the step:
//
//   explicit (forward) Euler:        v' = v + a dt,   r' = r + v  dt   (the OLD velocity)
//   semi-implicit (symplectic) Euler: v' = v + a dt,   r' = r + v' dt   (the NEW velocity)
//
// The lecture's "Euler integration" is the second: it uses the freshly updated velocity to
// move the particle. The change looks cosmetic but decides whether an undamped spring keeps
// its energy (symplectic) or gains energy every step until it explodes (explicit).
// We pass the inverse mass 1/m rather than m so that a pinned particle is simply 1/m = 0.
#pragma once

#include "clothlab/core/integrator.hpp"
#include "clothlab/core/particles.hpp"

namespace clothlab {

// Exercise ex01.3: one explicit Euler step of dt [s] for a particle at r [m] with velocity
// v [m/s], total force f [N] and inverse mass inv_m [1/kg].
PointState explicit_euler_step(const Vec3& r, const Vec3& v, const Vec3& f, double inv_m,
                               double dt);

// Exercise ex01.4: the same step with the lecture's semi-implicit (symplectic) Euler.
PointState symplectic_euler_step(const Vec3& r, const Vec3& v, const Vec3& f, double inv_m,
                                 double dt);

class ExplicitEuler final : public Integrator {
 public:
  std::string_view name() const override { return "explicit-euler"; }
  void advance(World& world, double dt) override;
  int force_evaluations_per_step() const override { return 1; }
};

class SymplecticEuler final : public Integrator {
 public:
  std::string_view name() const override { return "symplectic-euler"; }
  void advance(World& world, double dt) override;
  int force_evaluations_per_step() const override { return 1; }
};

}  // namespace clothlab
