// backend.hpp: the one door between the lecture's engine and a faster one.
//
// The world steps the lecture's way (world.cpp): forces summed effect by effect, the integrator
// moves the particles, the post-step effects apply, the guard checks. A backend may do some of
// that work another way, with the same floating-point operations on every particle in the same
// order, so that the state after a step is the same, bit for bit. The world asks it first and
// takes its own path for whatever it declines. The engine's fast path (engine/fast/) is one; a
// world without a backend (World::backend null, or `[engine] fast_path = false`) runs on the
// lecture's code alone. Nothing in engine/clothlab/ knows more of a backend than this file says.
#pragma once

#include <cstddef>
#include <string_view>
#include <vector>

#include "clothlab/core/types.hpp"

namespace clothlab {

class World;
class ForceEffect;
struct XpbdConstraints;
struct LinearSolveStats;
struct LocalGlobalSystem;
struct VbdGraph;

// What a backend took of a step (Backend::step).
struct BackendStep {
  // Steps 1-3 are done: the forces summed and every particle moved. The backend checked the
  // state the step started from as it read it, and threw the guard's error before moving
  // anything if that state was bad (Guard::check with before_step). Before moving anything it
  // also had the post-step effects record the state the step started from, as
  // World::record_step_start does (which World::step calls only when the step is declined).
  bool taken = false;
  // The first this many post-step effects of the world's list are applied as well.
  size_t post_step_done = 0;
  // Every particle was found within the guard's bounds right after its last change in the step.
  bool checked_after = false;
};

// What a backend took of a run of steps (Backend::steps).
struct BackendSteps {
  long taken = 0;      // whole steps taken, each as World::step takes it; 0: declined
  bool within = true;  // the state after the last of them is within the guard's bounds
};

class Backend {
 public:
  virtual ~Backend() = default;

  // f = the sum of every force effect of `world` at (x, v), as World::compute_forces_readable
  // sums it, bit for bit. False: declined, f is untouched and the world sums it itself.
  virtual bool sum_forces(const World& world, const Matrix3X& x, const Matrix3X& v,
                          Matrix3X& f) = 0;

  // Takes as much of one step of dt [s] as it can (see BackendStep); {} declines it all.
  virtual BackendStep step(World& world, double dt) = 0;
  // Takes up to `count` steps of dt [s] one after the other, each as World::step would take it
  // (the same bits): every force effect's set_time(world.t), the forces summed, every particle
  // moved, the state checked, then world.t += dt and ++world.steps. Between two of them the state
  // may stay in the backend's own layout; after the last, the world's particles hold it (x, v and
  // f, as after World::step), and a post-step effect, if the backend takes a world that has one,
  // has done to each step what World::step has it do. World::advance asks only for a world whose
  // guard has started, with no timer, and for no more steps than reach the guard's next energy
  // check. A state that fails the guard's test before the first step throws the guard's error
  // before anything moves; a step that leaves one is the last taken (within false: the world
  // then lets the guard throw). {} declines: nothing changed, not even the effects' time.
  virtual BackendSteps steps(World& /*world*/, double /*dt*/, long /*count*/) { return {}; }

  // The potential energy of `effect`, one of world's force effects, at x, as
  // effect.potential_energy(world.particles, x) computes it, bit for bit. False: declined, and
  // `energy` is untouched.
  virtual bool potential_energy(const World& /*world*/, const ForceEffect& /*effect*/,
                                const Matrix3X& /*x*/, double& /*energy*/) {
    return false;
  }

  // XPBD's projections of one substep of h [s] (integrators/xpbd.hpp): `iterations` times,
  // every constraint of `constraints` in its order, on world.particles.x, the substep having
  // started at x_old; lambda (one per constraint, 0 on entry) adds up each delta_lambda when
  // keep_lambda. The same bits as Xpbd::advance's own loop. False: declined, nothing changed.
  virtual bool xpbd_project(World& /*world*/, const XpbdConstraints& /*constraints*/,
                            const Matrix3X& /*x_old*/, double /*h*/, int /*iterations*/,
                            bool /*keep_lambda*/, std::vector<double>& /*lambda*/) {
    return false;
  }

  // One step of dt [s] of implicit Euler (integrators/implicit_euler.hpp) whole: f0, the
  // Jacobians, the conjugate-gradient solve of (M - dt D - dt^2 K) dv = dt (f0 + dt K v) to a
  // relative residual `tolerance` in at most `max_iterations` iterations, starting from dv (3 per
  // particle, the previous step's solution, or empty), then v += dv, x += dt v. dv is left
  // holding this step's solution, and the solve is counted in `stats`. Not the same bits as
  // ImplicitEuler::advance's own solve (another order of the same sums): the same solution to
  // within the tolerance. False: declined, nothing changed.
  virtual bool implicit_euler_step(World& /*world*/, double /*dt*/, double /*tolerance*/,
                                   int /*max_iterations*/, VectorX& /*dv*/,
                                   LinearSolveStats& /*stats*/) {
    return false;
  }

  // The local/global solver's iterations of one step (integrators/local_global.hpp): each time,
  // every spring's d from world.particles.x (the local step, into system.d), then the global
  // step's solve of system.a x = b_fixed + J d, written to the free particles' x. The same
  // local steps and right-hand sides as LocalGlobal::advance's own loop; the solve may be
  // another factorisation of the same matrix (the result within the tolerance tests/fast/
  // derives). False: declined, nothing changed.
  virtual bool local_global_iterate(World& /*world*/, LocalGlobalSystem& /*system*/,
                                    int /*iterations*/) {
    return false;
  }
  // Vertex Block Descent's sweeps of one step of h [s] (integrators/vbd.hpp): `iterations`
  // times, colour by colour of `graph`, each free vertex one Newton step (vbd_vertex_step) on
  // world.particles.x, the step having started at x_n, with y where inertia and the external
  // forces carry each vertex. The same bits as Vbd::advance's own loop. False: declined, nothing
  // changed.
  virtual bool vbd_sweeps(World& /*world*/, const VbdGraph& /*graph*/, const Matrix3X& /*x_n*/,
                          const Matrix3X& /*y*/, double /*h*/, int /*iterations*/) {
    return false;
  }
};

}  // namespace clothlab
