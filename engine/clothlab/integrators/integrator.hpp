// integrator.hpp: what advances the particles by one time step.
//
// An integrator asks the world for forces (as often as its method needs: once for Euler,
// several times for multi-stage methods) and moves positions and velocities forward by dt.
// Each method lives in its own file (euler.cpp, runge_kutta.cpp, verlet.cpp, implicit_euler.cpp)
// and is chosen by name in the scene. An integrator may keep state between steps (buffers, the
// previous positions of position Verlet), so each world owns its own.
#pragma once

#include <memory>
#include <span>
#include <string_view>

namespace clothlab {

class World;

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string_view name() const = 0;

  // Advances world.particles by dt [s]. Evaluates forces through world.compute_forces.
  virtual void advance(World& world, double dt) = 0;

  // Force evaluations per step, for reports ("4" for RK4). The implicit integrator also solves
  // a linear system; its cost is in its own statistics.
  virtual int force_evaluations_per_step() const = 0;

  // How the method steps the springs, when it has no time-step limit on them (XPBD: as
  // constraints; local/global: implicitly, by projections); "" for a method whose stable dt the
  // springs' stiffness bounds (lesson 08). The time-step advisor and the guard's advice ask it.
  virtual std::string_view springs_without_dt_limit() const { return ""; }
};

// The force-based integrators of lessons 01 to 08, which lesson 07 compares: what a scene may
// give in [integrator] method = "...", but for the methods of method_names() alone.
std::span<const std::string_view> integrator_names();

// Every name a scene may give in [integrator] method = "...": integrator_names(), lesson 12's
// position-based "xpbd", which moves particles by constraints instead of by spring forces, and
// lesson 13's "local-global", which solves implicit Euler by projections and a prefactored system.
std::span<const std::string_view> method_names();

// The integrator called `name`, or nullptr when there is none by that name.
std::unique_ptr<Integrator> make_integrator(std::string_view name);

}  // namespace clothlab
