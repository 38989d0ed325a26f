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

#include "clothlab/types.hpp"

namespace clothlab {

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
  double max_speed = 1e6;     // largest |velocity component| [m/s]; runaway energy shows here

  // Throws SimulationError if any position or velocity is NaN, infinite or beyond the bounds.
  void check(const World& world) const;
};

}  // namespace clothlab
