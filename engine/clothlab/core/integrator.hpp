// integrator.hpp: what advances the particles by one time step (step 3 of world.hpp).
//
// An integrator asks the world for forces (World::compute_forces, as often as its method needs:
// once for Euler, four times for RK4) and moves positions and velocities forward by dt. Each
// method lives in its own file of engine/clothlab/integrators/ (euler, runge_kutta, verlet,
// implicit_euler, xpbd, local_global, vbd), and a scene chooses one by name
// (integrators/methods.hpp). An integrator may keep state between steps (buffers, the previous
// positions of position Verlet), so each world owns its own.
#pragma once

#include <string>
#include <string_view>

namespace clothlab {

class World;

class Integrator {
 public:
  virtual ~Integrator() = default;

  // The method's name as a scene writes it in [integrator] method = "...".
  virtual std::string_view name() const = 0;

  // Advances world.particles by dt [s]. Evaluates forces through world.compute_forces.
  virtual void advance(World& world, double dt) = 0;

  // Force evaluations per step, for reports (4 for RK4). The implicit integrator also solves a
  // linear system; its cost is in its own statistics.
  virtual int force_evaluations_per_step() const = 0;

  // How many substeps one step is split into (XPBD, lesson 12: `substeps` of dt / substeps),
  // each ending with the contacts of PostStepEffect::each_substep; 1 for a method that takes the
  // step whole. World::step applies the last substep's contacts (world.hpp, step_time.hpp).
  virtual int substeps_per_step() const { return 1; }

  // How the method steps the springs when their stiffness does not limit its dt (XPBD: as
  // constraints; local/global: implicitly, by projections); "" for a method whose stable dt the
  // springs' stiffness bounds (lesson 08). The time-step advisor and the guard's advice ask it.
  virtual std::string_view springs_without_dt_limit() const { return ""; }

  // For such a method whose step solves the springs by iterations that may stop short of the
  // solution (VBD's sweeps): what the step does, in words that finish "if the springs are very
  // stiff, ... may leave them far from solved" ("its 1 sweep a step (iterations = 1)"); "" for a
  // method that cannot leave them so. The guard's advice on a run that blew up gives it.
  virtual std::string iterations_that_may_stop_short() const { return ""; }
};

}  // namespace clothlab
