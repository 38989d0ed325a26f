// world.hpp: the particles, the effects a scene named, and the step that ties them together.
//
// One step, in the lecture's order:
//   1. clear the force accumulators;
//   2. every force effect adds its forces;
//   3. the integrator advances positions and velocities (re-evaluating 1-2 if it needs to);
//   4. every post-step effect applies (collisions, plasticity, tearing);
//   5. the guard checks that the state is still finite and bounded.
// An integrator that moves every particle in one pass (the Euler methods) does steps 1-3 in that
// pass, and takes along the guard's checks and the post-step effects that act on each particle
// alone (a ground, a sphere): each particle meets them right after it moves (World::step).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "clothlab/effect.hpp"
#include "clothlab/fast_forces.hpp"
#include "clothlab/guard.hpp"
#include "clothlab/integrator.hpp"
#include "clothlab/particles.hpp"
#include "clothlab/threads.hpp"
#include "clothlab/triangles.hpp"

namespace clothlab {

// Wall time spent in each part of the step, filled in when World::timing points at it. Force
// effects and post-step effects are listed in the world's order.
struct StepTimes {
  std::vector<double> force_effects;      // [s] each force effect, over all evaluations
  std::vector<double> post_step_effects;  // [s] each post-step effect
  double integrator = 0.0;                // [s] the integrator's own work, forces excluded
  double guard = 0.0;                     // [s] the guard's checks
};

class World {
 public:
  Particles particles;
  std::vector<Triangle> triangles;  // the cloth's surface (lesson 03), for effects and output
  std::vector<std::unique_ptr<ForceEffect>> force_effects;
  std::vector<std::unique_ptr<PostStepEffect>> post_step_effects;
  std::unique_ptr<Integrator> integrator;
  Guard guard;

  double t = 0.0;  // simulated time [s]
  long steps = 0;  // steps taken so far

  // How often compute_forces has run: what a multi-stage integrator pays per step.
  mutable long force_evaluations = 0;
  mutable long fast_evaluations = 0;  // how many of them took the fast path (fast_forces.hpp)

  // When set (by `clothlab run --stats`), each step adds the time of each of its parts here.
  // The check costs one branch per effect per evaluation, never one per particle.
  StepTimes* timing = nullptr;

  // How the engine runs ([engine] in a scene, `clothlab run --threads N`).
  int threads = 1;        // threads a step may use (fast path, Euler, guard); 1: this one only
  bool fast_path = true;  // false: every force evaluation takes the readable path
  // Particles a thread sums and moves at once in a step's one pass (kPassBlock). Any value
  // gives the same bits; it sets only how much of the cloth each pass keeps in the cache.
  Index pass_block = kPassBlock;

  // Takes one step of dt [s] (steps 1-5 above).
  void step(double dt);

  // Steps 1-2 at an arbitrary state: f = sum of every force effect at (x, v) [N]. On the fast
  // path (fast_forces.hpp) when an effect has one, unless fast_path is off or --stats is timing
  // the effects; the two paths give the same f, bit for bit.
  void compute_forces(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const;

  // compute_forces, then move(begin, end, copies) on contiguous ranges of particles that cover
  // each once, as for_particles does: an integrator's update, which may read f and change the state
  // of particles [begin, end) only. On the fast path each thread moves its own particles as soon
  // as their forces are summed, a block at a time (pass_block), in the same pass over them, and
  // the guard can check each particle there (World::step); the move may read x, v and f from the
  // fast path's copies (MoveRange). So if an effect throws (an exercise not done yet), the
  // particles of earlier blocks, or of other threads, may have moved already.
  void compute_forces_then(const Matrix3X& x, const Matrix3X& v, Matrix3X& f,
                           const MoveRange& move) const;

  // The lecture's loop, the one the lessons show: clear f, then each effect adds its forces.
  void compute_forces_readable(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const;

  // Calls range(begin, end) on contiguous ranges of particles that cover them all once, each
  // range on one of the `threads` threads: for loops over particles whose iterations are
  // independent (an integrator moving each particle by its own force).
  void for_particles(const std::function<void(Index begin, Index end)>& range) const;

  // Diagnostics of the current state.
  double kinetic_energy() const;    // sum of 1/2 m |v|^2 [J] (pinned particles do not move)
  double potential_energy() const;  // sum over force effects [J]
  Vec3 momentum() const;            // sum of m v [kg m/s]

  // "gravity, gravitation; symplectic-euler": what a report or an error names as in play.
  std::string effects_in_play() const;

 private:
  bool takes_fast_path() const { return fast_path && !timing; }
  ThreadTeam* team() const;  // the threads of a step, or null for one thread

  mutable std::unique_ptr<ThreadTeam> team_;
  mutable FastScratch fast_;
  mutable StepChecks step_checks_;  // what the current step's one pass checks (World::step)
};

}  // namespace clothlab
