// guard.hpp: stops a simulation that has blown up, and says where and why.
//
// A step that is too large for the stiffness of a scene makes energy grow without bound; a
// division by a zero length makes a NaN that spreads to every particle within a few steps.
// The guard runs after every step and turns either into a SimulationError that names the step,
// the time, the first bad particle and the effects that were in play, instead of letting a run
// write pages of "nan".
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "clothlab/core/types.hpp"

namespace clothlab {

class ForceEffect;
class World;

class SimulationError : public std::runtime_error {
 public:
  SimulationError(const std::string& what, long step, Index particle)
      : std::runtime_error(what), step_(step), particle_(particle) {}
  long step() const { return step_; }
  Index particle() const { return particle_; }

 private:
  long step_;
  Index particle_;
};

struct Guard {
  double max_position = 1e6;  // largest |coordinate| a particle may reach [m]
  double max_speed = 1e6;     // largest |velocity component| [m/s]

  // The energy-runaway check. An unstable integrator adds energy a little every step; the
  // bounds above notice only once that has grown enormous, long after the cloth stopped
  // meaning anything. So every `energy_check_every` steps the guard compares the total energy
  // (kinetic + potential) with what it was at the start: a rise of more than
  // max_energy_growth times the scene's energy scale (the kinetic energy at the start plus
  // what each effect can give: the springs' stored energy, gravity over the scene's size, the
  // wind's 1/2 M |wind|^2, a moving pin's 1/2 M v_pin^2) is energy no force put in, and stops
  // the run.
  double max_energy_growth = 1e4;
  long energy_check_every = 32;

  // (An external field such as gravity adds, to that scale, the most energy it has released
  // so far: a ball that fell 100 m may move much faster than anything at the start.)

  // Throws SimulationError if any position or velocity is NaN, infinite or beyond the bounds.
  // `before_step` says the state is the one a step is about to start from (something outside
  // the integrator changed it since the last check): the error then names the step about to
  // be taken, before a NaN can spread from the particle that has it to its neighbours.
  void check(const World& world, bool before_step = false) const;

  // The same test without the search and the error: whether every position in columns
  // [begin, end) of x is within max_position and every velocity of v within max_speed (false
  // for a NaN). A pass that already has those particles in the cache checks them with it.
  bool within(const Matrix3X& x, const Matrix3X& v, Index begin, Index end) const;

  // Records the energy and the energy scale at the start of a run (World::step calls it
  // before the first step).
  void start(const World& world);

  // Throws SimulationError if the energy has run away since start(); call after a step.
  void check_energy(const World& world) const;

  double energy_start() const { return energy_start_; }
  double energy_scale() const { return energy_scale_ + released_; }

 private:
  double energy_start_ = 0.0;  // [J]
  double energy_scale_ = 0.0;  // [J] at the start
  Matrix3X x_start_;           // positions at the start [m]
  // Each force effect's potential energy at the start [J], the effect at its place in the
  // world's list: the external fields' released energy is measured from it
  // (ForceEffect::external_field).
  struct EffectStart {
    const ForceEffect* effect;
    double energy;
  };
  std::vector<EffectStart> effect_start_;
  mutable double released_ = 0;  // [J] the most energy external fields have released so far
};

}  // namespace clothlab
