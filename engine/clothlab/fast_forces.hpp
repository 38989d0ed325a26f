// fast_forces.hpp: the fast path of a force evaluation, on a structure-of-arrays copy of the state.
//
// World::compute_forces_readable is the lecture's loop: clear every force, then let each effect
// add its forces, particle by particle or spring by spring, on the engine's own layout (one
// column x, y, z per particle). It is what the lessons show. The fast path computes the same
// sums on another layout:
//
//   1. copy x and v into SoA3 (all x components, then all y, then all z) and clear f there;
//   2. every effect adds its forces there (ForceEffect::add_forces_soa): a loop over particles,
//      or over a run of springs (spring_damper.hpp), reads each component in memory order, so
//      the compiler computes four springs at once with vector instructions, through the same
//      exercise kernels. With threads, each takes a contiguous range of particles and every
//      effect adds the forces on that range only: no two threads write the same force;
//   3. copy f back. An integrator that moves each particle by its own force (the Euler
//      methods) moves it right there, in the pass that summed its force (compute_forces_then),
//      reading its state from the copies. That pass takes each thread's particles a block at a
//      time (kPassBlock): every effect adds its forces on the block, then the block moves.
//
// Each particle receives the same floating-point operations in the same order as on the readable
// path, so the two agree bit for bit, with any number of threads (tests/engine/fast_path.cpp).
// An effect without such a path (buoyancy, gravitation) adds its forces with add_forces, on the
// engine's layout, in its turn: f is copied across when the layout changes.
#pragma once

#include <functional>
#include <vector>

#include "clothlab/effect.hpp"

namespace clothlab {

class World;
class ThreadTeam;

// The fast path's copies of the state, kept by the world between evaluations.
struct FastScratch {
  SoA3 x, v, f;
  std::vector<char> soa;  // which force effects take the fast path, by their place in the world

  // Room for n particles in x, v and f, each with rows spaced its own way (see fast_forces.cpp):
  // the columns past n are padding.
  void resize(Index n);
};

// An integrator's update of particles [begin, end) (World::compute_forces_then): it may read f
// and change the state of those particles only. With `copies`, the fast path's copies hold,
// for those particles, the same x, v and f as the engine's layout, bit for bit, in a layout
// whose loops the compiler vectorises across particles: the update may read them instead.
using MoveRange = std::function<void(Index begin, Index end, const FastScratch* copies)>;

// The guard's checks of a step (World::step) that a step's one pass takes on, when its
// integrator moves every particle in that pass (Integrator::moves_in_one_pass): each particle is
// checked while the pass has it in the cache, instead of in passes of their own over the state.
// The post-step effects that act on each particle alone and lead the world's list (a ground, a
// sphere) ride along too: after_move applies them to each range right after it moves.
struct StepChecks {
  bool armed = false;        // World::step sets it; the step's compute_forces_then clears it
  bool end = false;          // check the state after the move too (no other post-step effect)
  bool end_checked = false;  // the pass checked every particle after moving it,
  bool end_within = false;   // and found them all within the guard's bounds
  // The post-step effects that ride along: the first post_in_pass of the world's list, applied
  // by after_move to each range right after it moves, for a step of dt [s].
  size_t post_in_pass = 0;
  double dt = 0.0;
  const std::function<void(Index begin, Index end)>* after_move = nullptr;
};

// Asks every force effect whether it has a fast path (once per evaluation, on one thread: an
// effect may update its caches) and notes the answers in scratch. Whether any has one.
bool prepare_fast_forces(const World& world, FastScratch& scratch);

// Forces at (x, v) into f, as World::compute_forces_readable computes them, through the fast
// path, after prepare_fast_forces. `team` may be null (one thread). Then, if `move` is given,
// move on ranges that cover every particle once (World::compute_forces_then): where the last
// effect has a fast path, each thread calls it on its own particles, kPassChunk at a time,
// right after copying their forces back, in the pass that summed them, with the copies. With
// `checks`, (x, v) is the state a step starts from: it is checked as it is copied (a bad one
// throws the guard's error before any particle moves), and the new state as it is moved if
// checks->end.
void fast_forces(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f,
                 FastScratch& scratch, ThreadTeam* team, const MoveRange* move = nullptr,
                 StepChecks* checks = nullptr);

// Particles a thread copies, checks or moves at once: their x, v and f in the engine's layout
// (36 KiB) stay in the second-level cache from one of these to the next.
inline constexpr Index kPassChunk = 512;

// Particles a thread takes through every force effect and then moves, in a step's one pass
// (World::pass_block): their x, v and f in the fast layout (72 bytes a particle, 576 KiB) stay
// in the second-level cache from one effect to the next, where a whole cloth would stream
// through it once per effect. A spring with an end on each side of a border is evaluated on
// both sides, each adding only to its own end: for a grid, about 1 / R more springs, R = rows
// per block (32 for a 256-wide cloth). engine/SPEED.md has the measurements behind the size.
inline constexpr Index kPassBlock = 8192;

}  // namespace clothlab
