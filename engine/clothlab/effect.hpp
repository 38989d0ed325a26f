// effect.hpp: the two kinds of effect a scene can switch on.
//
// Lecture, "Physics Simulation": 1. compute forces, 2. integrate motion, repeat.
// A ForceEffect takes part in step 1 (gravity, springs, wind, ...). A PostStepEffect runs
// once after the integrator has moved the particles (collisions, plasticity, tearing).
// A scene constructs only the effects it names: an effect it does not name is never built,
// so it costs nothing at all. The virtual call happens once per effect per force evaluation,
// never once per particle.
#pragma once

#include <string_view>

#include "clothlab/particles.hpp"

namespace clothlab {

class World;

class ForceEffect {
 public:
  virtual ~ForceEffect() = default;

  // The effect's name as a scene writes it, e.g. "gravity"; used in reports and errors.
  virtual std::string_view name() const = 0;

  // Adds this effect's force on every particle into f [N], for positions x [m] and velocities
  // v [m/s]. Multi-stage integrators call this at trial states, so an effect reads x and v from
  // the arguments, never from p.x and p.v (p supplies masses and other per-particle data).
  virtual void add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                          Matrix3X& f) const = 0;

  // The potential energy this effect stores at positions x [J]; 0 for forces without one.
  virtual double potential_energy(const Particles& /*p*/, const Matrix3X& /*x*/) const {
    return 0.0;
  }
};

class PostStepEffect {
 public:
  virtual ~PostStepEffect() = default;
  virtual std::string_view name() const = 0;

  // Applies the effect once the integrator has advanced the particles by dt [s]. It gets the
  // whole world: some post-step effects change more than particles (tearing removes springs
  // and triangles).
  virtual void apply(World& world, double dt) = 0;
};

}  // namespace clothlab
