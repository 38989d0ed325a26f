// world.hpp: the particles, the effects a scene named, and the step that ties them together.
//
// One step of dt from time t, in the lecture's order (after the effects have been told the time,
// set_time, and have recorded what they need of the state the step starts from, before_step):
//   1. clear the force accumulators;
//   2. every force effect adds its forces;
//   3. the integrator advances positions and velocities (re-evaluating 1-2 if it needs to);
//   4. every post-step effect applies (collisions, plasticity, tearing);
//   5. the guard checks that the state is still finite and bounded (and it checked it before 1).
// A backend (backend.hpp) may take some of it another way, with the same result, bit for bit.
//
// Substeps, and the time each post-step effect is told (step_time.hpp). An integrator may split
// the step into n = Integrator::substeps_per_step() substeps of h = dt / n (XPBD, lesson 12).
//   - A contact with a fixed solid (PostStepEffect::each_substep: ground, plane, sphere) applies
//     after every substep: the integrator calls before_step at the start of substeps 1 to n-1 and
//     apply at the end of substeps 0 to n-2, with StepTime::of_substep(t, dt, k, n); World::step
//     calls before_step for substep 0 (above) and apply for substep n-1, after the integrator.
//   - Every other post-step effect (pins that move, plasticity, tearing, strain limiting,
//     self-collision) applies once, in World::step, with StepTime::whole(t, dt): h = dt.
// With n = 1 the two are the same: substep 0 of 1, h = dt. World::t stays t until every
// post-step effect has applied; StepTime::end() says when the span an application closes ends.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "clothlab/core/backend.hpp"
#include "clothlab/core/effect.hpp"
#include "clothlab/core/guard.hpp"
#include "clothlab/core/integrator.hpp"
#include "clothlab/core/particles.hpp"
#include "clothlab/core/step_timer.hpp"
#include "clothlab/core/threads.hpp"
#include "clothlab/core/triangles.hpp"

namespace clothlab {

class World {
 public:
  Particles particles;
  std::vector<Triangle> triangles;  // the cloth's surface (lesson 03), for effects and output
  std::vector<std::unique_ptr<ForceEffect>> force_effects;
  std::vector<std::unique_ptr<PostStepEffect>> post_step_effects;
  std::unique_ptr<Integrator> integrator;
  Guard guard;
  // What may take force sums or whole steps the fast way (backend.hpp); null: none, every step
  // runs on the lecture's code. A scene gets the engine's fast path unless it says
  // `[engine] fast_path = false`.
  std::unique_ptr<Backend> backend;

  double t = 0.0;  // simulated time [s]
  long steps = 0;  // steps taken so far

  // How often compute_forces has run: what a multi-stage integrator pays per step.
  mutable long force_evaluations = 0;
  mutable long backend_evaluations = 0;  // how many of them the backend made

  // When set (StepTimer::attach, by `clothlab run --stats`), each step adds the time of each of
  // its parts there, on whichever path it takes (step_timer.hpp).
  StepTimer* timer = nullptr;

  // Threads a step may use (the backend, the guard); 1: this one only. ([engine] threads in a
  // scene, `clothlab run --threads N`.)
  int threads = 1;
  // When set (by `clothlab bench roofline`), the passes of for_particles_with_barrier add there
  // where their threads' time went (ThreadProfile).
  ThreadProfile* thread_profile = nullptr;

  // Takes one step of dt [s] (steps 1-5 and the substep contract above).
  void step(double dt);
  // Takes `count` steps of dt [s]: the same as calling step(dt) `count` times, bit for bit, the
  // guard's checks and errors included. A backend may take several at once without handing the
  // state back between them (Backend::steps), for a world with no post-step effect; nothing
  // outside the world may read or change its particles until advance returns.
  void advance(double dt, long count);

  // Every post-step effect records what it needs of the state the step starts from
  // (PostStepEffect::before_step). step() calls it when no backend takes the step; a backend
  // that takes it records the same before anything moves (backend.hpp).
  void record_step_start();

  // Steps 1-2 at an arbitrary state: f = sum of every force effect at (x, v) [N]. The backend
  // sums them when it can; else the lecture's loop below does. Both give the same f, bit for bit.
  void compute_forces(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const;

  // The lecture's loop, the one the lessons show: clear f, then each effect adds its forces.
  void compute_forces_readable(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const;

  // Calls range(begin, end) on contiguous ranges of particles that cover them all once, each
  // range on one of the `threads` threads: for loops over particles whose iterations are
  // independent (the guard's checks, a backend's passes).
  void for_particles(const std::function<void(Index begin, Index end)>& range) const;
  // The same, where range may wait at barrier.wait() until every thread has done the part of its
  // work before it (for_ranges_with_barrier): a pass in two parts for one wake of the threads.
  // Its passes are the fast engine's (a step's, a force sum's): the time each thread worked in one
  // moves the split of the particles for the passes after it (balance_bounds), so that a thread
  // whose particles cost more (the part of a cloth that lies on the ground) gets fewer of them.
  void for_particles_with_barrier(
      const std::function<void(Index begin, Index end, const Barrier& barrier)>& range) const;
  // Where each thread's particles begin, threads + 1 bounds, the last the number of particles:
  // for_particles and for_particles_with_barrier give thread t [bounds[t], bounds[t + 1]). The
  // even split until a pass of for_particles_with_barrier moves it, and again when the number of
  // threads or of particles changes. Any split gives the same bits.
  const std::vector<Index>& particle_bounds() const;
  // Sets that split (a test's, or a benchmark's): threads + 1 bounds, from 0 up to the number of
  // particles, none smaller than the one before; std::invalid_argument otherwise.
  void set_particle_bounds(std::vector<Index> bounds);
  // The same for any n items (a backend's loop over independent constraints): contiguous
  // ranges that cover [0, n) once each, one a thread.
  void for_items(Index n, const std::function<void(Index begin, Index end)>& range) const;

  // Diagnostics of the current state.
  double kinetic_energy() const;  // sum of 1/2 m |v|^2 [J] (pinned particles do not move)
  // Sum over force effects [J], each effect's term the backend's when it computes it (the same
  // bits), else the effect's own; with `each`, effect e's term also in (*each)[e].
  double potential_energy(std::vector<double>* each = nullptr) const;
  Vec3 momentum() const;  // sum of m v [kg m/s]

  // "gravity, gravitation; symplectic-euler": what a report or an error names as in play.
  std::string effects_in_play() const;

  // The times the steps so far have woken the threads (ThreadTeam::runs), 0 on one thread.
  long thread_wakes() const { return team_ ? team_->runs() : 0; }

 private:
  ThreadTeam* team() const;  // the threads of a step, or null for one thread

  mutable std::unique_ptr<ThreadTeam> team_;
  mutable std::vector<Index> particle_bounds_;  // particle_bounds()
  mutable std::vector<double> pass_work_;       // each thread's work in the last pass [s]
};

}  // namespace clothlab
