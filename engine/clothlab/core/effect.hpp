// effect.hpp: the two kinds of effect a scene can switch on.
//
// Lecture, "Physics Simulation": 1. compute forces, 2. integrate motion, repeat.
// A ForceEffect takes part in step 1 (gravity, springs, wind, ...). A PostStepEffect runs
// once after the integrator has moved the particles (collisions, plasticity, tearing).
// A scene constructs only the effects it names: an effect it does not name is never built,
// so it costs nothing at all. The virtual call happens once per effect per force evaluation,
// never once per particle.
#pragma once

#include <cmath>
#include <string_view>

#include "clothlab/core/particles.hpp"
#include "clothlab/core/step_time.hpp"

namespace clothlab {

class World;

using Mat3 = Eigen::Matrix3d;

// Where an effect writes its force Jacobians for the implicit integrator (lesson 07): how its
// forces change when positions (df/dx) and velocities (df/dv) change, as 3x3 blocks.
class ForceJacobians {
 public:
  virtual ~ForceJacobians() = default;

  // A force between i and j that is equal and opposite and depends on the differences
  // x_j - x_i and v_j - v_i (a spring-damper). dfdx = df_i/dx_j and dfdv = df_i/dv_j, both
  // symmetric; the other three blocks follow: df_i/dx_i = -dfdx, df_j/dx_i = dfdx,
  // df_j/dx_j = -dfdx, and the same for dfdv.
  virtual void add_pair(Index i, Index j, const Mat3& dfdx, const Mat3& dfdv) = 0;

  // A force on particle i alone: dfdx = df_i/dx_i and dfdv = df_i/dv_i, both symmetric.
  virtual void add_self(Index i, const Mat3& dfdx, const Mat3& dfdv) = 0;
};

class ForceEffect {
 public:
  virtual ~ForceEffect() = default;

  // The effect's name as a scene writes it, e.g. "gravity"; used in reports and errors.
  virtual std::string_view name() const = 0;

  // Called by World::step before each step with the time t [s] the step starts at. An effect
  // whose parameters change in time (a gust of wind) takes their values at t for the whole
  // step, at every trial state of the integrator.
  virtual void set_time(double /*t*/) {}

  // Adds this effect's force on every particle into f [N], for positions x [m] and velocities
  // v [m/s]. Multi-stage integrators call this at trial states, so an effect reads x and v from
  // the arguments, never from p.x and p.v (p supplies masses and other per-particle data).
  virtual void add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                          Matrix3X& f) const = 0;

  // The potential energy this effect stores at positions x [J]; 0 for forces without one.
  virtual double potential_energy(const Particles& /*p*/, const Matrix3X& /*x*/) const {
    return 0.0;
  }

  // The energy [J] this effect can give the particles, as a yardstick for the guard's
  // energy-runaway check: for a conservative force the energy it stores at x, |U(x)|; a force
  // that can feed energy in (gravity over the scene's size, wind) says how much. `size` [m] is
  // the diagonal of the particles' bounding box.
  virtual double energy_scale(const Particles& p, const Matrix3X& x, double /*size*/) const {
    return std::abs(potential_energy(p, x));
  }

  // Whether this is an external field (gravity, gravitation, buoyancy): between positions x0
  // and x it has released |U(x) - U(x0)| [J] of energy, and a ball that has fallen far has that
  // much to show for it. Springs and other internal forces release none: their energy is what a
  // runaway shows up in. The guard widens its yardstick by the most released so far (it keeps
  // U(x0) from the start and takes U(x) from the energy it checks).
  virtual bool external_field() const { return false; }

  // Adds this effect's force Jacobians at (x, v) for the implicit integrator. An effect that
  // adds none (gravity, wind) is treated explicitly: its force enters the step, its Jacobian
  // does not. Returns whether it added any.
  virtual bool add_jacobians(const Particles& /*p*/, const Matrix3X& /*x*/, const Matrix3X& /*v*/,
                             ForceJacobians& /*jacobians*/) const {
    return false;
  }
};

class PostStepEffect {
 public:
  virtual ~PostStepEffect() = default;
  virtual std::string_view name() const = 0;

  // Called at the start of every step, before anything moves. An effect that needs the state the
  // step starts from records it here: a contact needs where each particle was, so that static
  // friction can hold a particle where it stood (ground_collision.hpp).
  virtual void before_step(const World& /*world*/) {}

  // Applies the effect once the integrator has advanced the particles over the span `time`
  // closes: the whole step, or a substep for an effect that applies each substep (see below and
  // step_time.hpp). It gets the whole world: some post-step effects change more than particles
  // (tearing removes springs and triangles).
  virtual void apply(World& world, const StepTime& time) = 0;

  // The energy [J] this effect can give the particles, as ForceEffect::energy_scale says: a pin
  // that moves can drive them.
  virtual double energy_scale(const Particles& /*p*/, double /*size*/) const { return 0.0; }

  // True for a contact with a fixed solid (the ground, a plane, a sphere), which changes each
  // particle from that particle's own state alone. An integrator that splits its step into
  // substeps (XPBD, lesson 12) treats each substep as a step for such an effect: before_step at
  // the substep's start, apply at its end with that substep's StepTime, so that the cloth meets
  // the solid within a substep rather than a whole step late. The integrator applies substeps 0
  // to n-2; World::step applies the last, n-1, after the step as always. Tearing, plasticity and
  // the others see whole steps (StepTime::whole).
  virtual bool each_substep() const { return false; }
};

}  // namespace clothlab
