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

#include "clothlab/particles.hpp"

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

// Per-particle vectors stored as a structure of arrays for the fast path (fast_forces.hpp): the
// x components of every particle, then the y components, then the z components, each row
// contiguous. Column i is still particle i (s.col(i) is a Vec3 expression), but a loop over
// particles reads each component in memory order, which lets the compiler vectorise it. The fast
// path's copies have a few more columns than there are particles (fast_forces.cpp says why), so
// row c of s starts at s.data() + c * s.cols(): use s.cols() as the stride, never the number
// of particles.
using SoA3 = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>;

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

  // The energy [J] this effect can give the particles, as a yardstick for the guard's
  // energy-runaway check: for a conservative force the energy it stores at x, |U(x)|; a force
  // that can feed energy in (gravity over the scene's size, wind) says how much. `size` [m] is
  // the diagonal of the particles' bounding box.
  virtual double energy_scale(const Particles& p, const Matrix3X& x, double /*size*/) const {
    return std::abs(potential_energy(p, x));
  }

  // The energy [J] an external field (gravity, gravitation, buoyancy) has released between
  // positions x0 and x, |U(x) - U(x0)|: a ball that has fallen far has that much energy to
  // show for it. Springs and other internal forces release none: their energy is what a
  // runaway shows up in. The guard widens its yardstick by the most released so far.
  virtual double released_energy(const Particles& /*p*/, const Matrix3X& /*x0*/,
                                 const Matrix3X& /*x*/) const {
    return 0.0;
  }

  // Adds this effect's force Jacobians at (x, v) for the implicit integrator. An effect that
  // adds none (gravity, wind) is treated explicitly: its force enters the step, its Jacobian
  // does not. Returns whether it added any.
  virtual bool add_jacobians(const Particles& /*p*/, const Matrix3X& /*x*/, const Matrix3X& /*v*/,
                             ForceJacobians& /*jacobians*/) const {
    return false;
  }

  // The fast path (fast_forces.hpp). An effect that can add its forces on the structure-of-
  // arrays copy of the state says so here, and may update what it caches for it (called once
  // per evaluation, on one thread). The others make the world take the readable path.
  virtual bool adds_soa(const Particles& /*p*/) const { return false; }

  // The same forces as add_forces on particles [begin, end) only, added into those columns of
  // f, with the same floating-point operations on each particle in the same order, so that the
  // two paths agree bit for bit. It reads x and v anywhere (a spring reaches out of the range)
  // and writes f nowhere else: the fast path gives different ranges to different threads.
  virtual void add_forces_soa(const Particles& /*p*/, const SoA3& /*x*/, const SoA3& /*v*/,
                              SoA3& /*f*/, Index /*begin*/, Index /*end*/) const {}
};

class PostStepEffect {
 public:
  virtual ~PostStepEffect() = default;
  virtual std::string_view name() const = 0;

  // Applies the effect once the integrator has advanced the particles by dt [s]. It gets the
  // whole world: some post-step effects change more than particles (tearing removes springs
  // and triangles).
  virtual void apply(World& world, double dt) = 0;

  // Whether apply changes each particle from that particle's own position, velocity and mass
  // alone, and nothing else (a ground, a sphere). A step whose integrator moves every particle
  // in one pass then applies the effect in that pass, range by range, right after moving each
  // range (apply_range), while those particles are still in the cache, instead of in a pass of
  // its own over the whole state (World::step).
  virtual bool acts_per_particle() const { return false; }
  // apply on particles [begin, end) only, for an effect that acts_per_particle. Threads may call
  // it on different ranges at once.
  virtual void apply_range(Particles& /*p*/, double /*dt*/, Index /*begin*/, Index /*end*/) const {}
};

}  // namespace clothlab
