// resident.hpp: steps of an Euler method one after the other with the state kept in the fast
// layout between them (Backend::steps: FastEngine::steps, FloatRoom::steps).
//
// World::step hands the state back to the world after every step: the fast path copies x and v
// into its layout at the start and writes x, v and f back at the end, and the float room rounds
// them to float and back as well. When the world asks for several steps at once
// (World::advance) and nothing outside the step reads or changes the particles between them (no
// post-step effect), the state can stay in the fast layout: two copies of it, the one a step
// reads and the one its move writes, in turn. The state is read from the world once, before the
// first step, and written back once, after the last. Each step does the same operations on the
// same numbers as World::step does, so the state after each is the same, bit for bit (a float
// is exactly the double it is written as, and rounds back to itself).
//
// All the steps are one job of the world's threads: each thread takes its particles through
// every step, and waits at a barrier between two steps (the next reads the x and v every thread
// has just written): one barrier a step, the last thread to reach it telling each force effect
// the next step's time (set_time) before the others go on. The world's time and counts move
// after the job, by the steps taken.
#pragma once

#include <atomic>
#include <functional>

#include "clothlab/core/backend.hpp"
#include "clothlab/core/threads.hpp"
#include "clothlab/core/world.hpp"
#include "fast/copies.hpp"

namespace clothlab::fast {

// Takes up to `count` steps of dt of `world` (Backend::steps' contract) on the copies of `r`.
// add(b0, b1, x, v, f) adds every force effect's forces on particles [b0, b1) into f, from x
// and v; move(c0, c1, now, next) moves particles [c0, c1) from now's x, v and f into next's x and
// v, and returns whether they are within the guard's bounds. Particles go through each step
// `block` at a time: their forces cleared and summed, then moved, in chunks of `chunk`. A block's
// forces are cleared just before its effects add to them, while they are still in the cache:
// an effect adds to the particles of the block it is given and to no others (FastForceOf::add).
template <class S, class Add, class Move>
BackendSteps resident_steps(World& world, double dt, long count, ResidentOf<S>& r, Index block,
                            Index chunk, Add add, Move move) {
  Particles& p = world.particles;
  const Index n = p.size();
  r.resize(n);
  p.f.resize(3, n);
  // The world's time as the steps reach it, advanced as World::step advances world.t (the same
  // additions, so the same bits); world.t itself moves after the job, with the steps taken.
  double t = world.t;
  for (const auto& effect : world.force_effects)
    effect->set_time(t);  // the first step's; the last thread to finish a step sets the next's
  std::atomic<bool> start_within = true, end_within = true;
  // What happens between two steps, once, on the last thread to finish the first of them, while
  // the others wait at the barrier (Barrier::wait): whether that step was the last, and if not,
  // the next step's time told to every effect. `taken` counts the steps every thread has done
  // (a step that throws, or whose next time does, is not among them); every thread reads `last`
  // once the barrier lets it go.
  long taken = 0;
  bool last = false;
  const std::function<void()> between_steps = [&] {
    if (taken + 1 == count || !end_within) {
      ++taken;
      last = true;
      return;
    }
    t += dt;
    for (const auto& effect : world.force_effects)
      effect->set_time(t);
    ++taken;
  };
  const auto steps = [&](Index begin, Index end, const Barrier& barrier) {
    const bool x_within =
        to_soa_within(begin, end, p.x.data(), r.a.x.data(), r.a.x.cols(), world.guard.max_position);
    const bool v_within =
        to_soa_within(begin, end, p.v.data(), r.a.v.data(), r.a.v.cols(), world.guard.max_speed);
    if (!x_within || !v_within) start_within = false;
    barrier.wait();
    if (!start_within) return;  // nothing moves; the guard's error follows
    CopiesOf<S>* now = &r.a;
    CopiesOf<S>* next = &r.b;
    try {
      for (;;) {
        for (Index b0 = begin; b0 < end; b0 += block) {
          const Index b1 = std::min(b0 + block, end);
          now->f.middleCols(b0, b1 - b0).setZero();
          add(b0, b1, now->x, now->v, now->f);
          for (Index c0 = b0; c0 < b1; c0 += chunk) {
            if (!move(c0, std::min(c0 + chunk, b1), *now, *next)) end_within = false;
          }
        }
        // Every particle has moved: the next step may read any of them, at its own time.
        barrier.wait(between_steps);
        if (last) break;
        std::swap(now, next);
      }
    } catch (...) {
      // A step that threw (here or on another thread) is not taken: the world keeps the state
      // it started from, and the steps before it.
      from_soa(begin, end, now->x.data(), now->x.cols(), p.x.data());
      from_soa(begin, end, now->v.data(), now->v.cols(), p.v.data());
      throw;
    }
    // The state after the last step, and the forces it moved by, to the world.
    from_soa(begin, end, next->x.data(), next->x.cols(), p.x.data());
    from_soa(begin, end, next->v.data(), next->v.cols(), p.v.data());
    from_soa(begin, end, now->f.data(), now->f.cols(), p.f.data());
  };
  // What World::step does after each step's work, for the steps taken.
  const auto account = [&world, dt](long steps_taken) {
    for (long k = 0; k < steps_taken; ++k) {
      world.t += dt;
      ++world.steps;
      ++world.force_evaluations;
      ++world.backend_evaluations;
    }
  };
  try {
    world.for_particles_with_barrier(steps);
  } catch (...) {
    account(taken);  // the steps before the one that threw
    throw;
  }
  if (!start_within) {
    world.guard.check(world, /*before_step=*/true);  // names the particle and throws
    return {};
  }
  account(taken);
  return {taken, end_within.load()};
}

}  // namespace clothlab::fast
