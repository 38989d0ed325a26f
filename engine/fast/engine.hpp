// engine.hpp: the fast engine, the world's backend (clothlab/core/backend.hpp) unless a scene says
// `[engine] fast_path = false`.
//
// World::compute_forces_readable is the lecture's loop: clear every force, then let each effect
// add its forces, particle by particle or spring by spring, on the engine's own layout (one
// column x, y, z per particle). It is what the lessons show. The fast engine computes the same
// sums on another layout (copies.hpp):
//
//   1. copy x and v into the copies (all x components, then all y, then all z) and clear f there;
//   2. every effect it knows (forces.hpp) adds its forces there: a loop over particles, or over
//      a run of springs (springs.hpp), reads each component in memory order, so the compiler
//      computes four springs at once with vector instructions, through the same exercise
//      kernels. With threads, each takes a contiguous range of particles and every effect adds
//      the forces on that range only: no two threads write the same force. The ranges follow
//      the threads' work (World::particle_bounds: a pass that one thread took longer over
//      gives it fewer particles in the next);
//   3. copy f back.
//
// With threads, the copy and the sums are one job of the team: each thread copies its own
// particles, waits at a barrier until every thread has (a spring at the border of two ranges
// reads the other range's copies), then sums its particles' forces and copies them back. A
// force sum wakes the threads once (ThreadTeam::sync, World::for_particles_with_barrier).
//
// A step of an Euler method (each particle moves by its own force alone) goes further: each
// particle moves right there, in the pass that summed its force, reading its state from the
// copies: the whole step is that one job. That pass takes each thread's particles a block at a time
// (pass_block): every effect adds its forces on the block, then the block moves. The pass also
// checks each particle for the guard as it copies it and after it moves, and the ground and the
// sphere, when they lead the world's post-step effects, push each particle out right after it
// moves (each thread records its particles' start for them as it copies them): the same checks
// and the same contacts, without passes of their own over the whole state.
//
// Several steps at once (World::advance, Backend::steps), in a world with no post-step effect
// whose force effects all have a fast form, keep the state in the copies between them
// (resident.hpp): two copies, the one a step reads and the one its move writes, in turn; x and v
// are copied in before the first step and x, v and f written back after the last. All the steps
// are one job of the threads, with barriers between them. `clothlab run` takes the steps between
// two frames that way, and `clothlab bench speed` times the engine so.
//
// Each particle receives the same floating-point operations in the same order as on the
// lecture's path, so the two agree bit for bit, with any number of threads and any block size
// (tests/fast/). An effect the engine does not know (buoyancy, gravitation) adds its forces with
// add_forces, on the engine's layout, in its turn: f is copied across when the layout changes.
// SPEED.md has the measurements behind each choice.
//
// Of an XPBD step it takes the projections only (xpbd_project, in xpbd.cpp): colour by colour
// of the integrator's constraint colouring, each colour split over the threads, with the bits
// of the integrator's own loop.
//
// Of an implicit Euler step it takes the whole (implicit_euler_step, in implicit.cpp): the
// Jacobians spring by spring and a matrix-free conjugate-gradient solve on the threads.
//
// Of a local/global step it takes the iterations (local_global.cpp): the local steps and
// right-hand sides with the integrator's bits, the solves by CHOLMOD.
//
// Of a VBD step it takes the sweeps (vbd.cpp): colour by colour, each colour split over the
// threads, with the bits of the integrator's own loop.
//
// With `[engine] precision = "float"` it hands each step to the float room (float_room.hpp): the
// same pass in single precision, for the Euler methods and the effects listed there (and runs
// of steps with the state kept in float between them).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <typeinfo>
#include <vector>

#include "clothlab/core/backend.hpp"
#include "fast/copies.hpp"
#include "fast/forces.hpp"

namespace clothlab {
class Ground;
class Sphere;
class StepStart;
struct Guard;
}  // namespace clothlab

namespace clothlab::fast {

// Particles a thread copies, checks or moves at once: their x, v and f in the engine's layout
// (36 KiB) stay in the second-level cache from one of these to the next.
inline constexpr Index kPassChunk = 512;

// Particles a thread takes through every force effect and then moves, in a step's one pass
// (FastEngine::pass_block): their x, v and f in the fast layout (72 bytes a particle, 576 KiB)
// stay in the second-level cache from one effect to the next, where a whole cloth would stream
// through it once per effect. A spring with an end on each side of a border is evaluated on
// both sides, each adding only to its own end: for a grid, about 1 / R more springs, R = rows
// per block (32 for a 256-wide cloth). SPEED.md has the measurements behind the size.
inline constexpr Index kPassBlock = 8192;

// A post-step effect that rides along in the engine room's step: a contact, which changes each
// particle from its own state alone (Ground::contact, Sphere::contact).
struct Contact {
  const Ground* ground = nullptr;
  const Sphere* sphere = nullptr;
};

struct ImplicitSolver;
struct LocalGlobalRoom;  // local_global.cpp
class FloatRoom;         // float_room.hpp

class FastEngine final : public Backend {
 public:
  // Particles a thread sums and moves at once in a step's one pass (kPassBlock). Any value
  // gives the same bits; it sets only how much of the cloth each pass keeps in the cache.
  Index pass_block = kPassBlock;

  // XPBD's projections colour by colour (xpbd.cpp): fewer constraints in a colour than this
  // are projected on one thread, where waking the others would cost more than they save. Any
  // value gives the same bits.
  Index xpbd_split = 2048;

  // Vertex Block Descent's sweeps colour by colour (vbd.cpp): fewer vertices in a colour than
  // this are stepped on one thread. Any value gives the same bits.
  Index vbd_split = 1024;

  // Implicit Euler's conjugate gradients (implicit.cpp), preconditioned by the inverse of each
  // particle's 3x3 diagonal block of the matrix (block Jacobi), or of its diagonal alone (as
  // the lecture's solver is). SPEED.md measures what the blocks save.
  enum class Preconditioner { diagonal, block_jacobi };
  Preconditioner implicit_preconditioner = Preconditioner::block_jacobi;

  // The numbers a step computes with: double (the fast path above, bit for bit the readable
  // path), or float (`[engine] precision = "float"`): every step in the float room
  // (float_room.hpp), which covers the Euler methods and the effects it lists, and throws on
  // anything else. Force sums asked for outside a step (sum_forces) stay double.
  enum class Precision { float64, float32 };
  Precision precision = Precision::float64;

  bool sum_forces(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f) override;
  BackendStep step(World& world, double dt) override;
  // Steps of an Euler method whose force effects all have a fast form, in a world with no
  // post-step effect, the state kept in the fast layout between them (resident.hpp); in float
  // in the float room.
  BackendSteps steps(World& world, double dt, long count) override;
  bool potential_energy(const World& world, const ForceEffect& effect, const Matrix3X& x,
                        double& energy) override;
  bool xpbd_project(World& world, const XpbdConstraints& constraints, const Matrix3X& x_old,
                    double h, int iterations, bool keep_lambda,
                    std::vector<double>& lambda) override;
  // xpbd_project's passes (the fast layout, the colours in order, each split over the threads,
  // the same loads and stores) with each projection replaced by a few multiply-adds: no square
  // root, no division. What the access pattern alone costs: the bound `clothlab bench methods
  // --speed` prints beside an XPBD iteration. It moves the particles by next to nothing and is
  // no method.
  void xpbd_access_passes(World& world, const XpbdConstraints& constraints, const Matrix3X& x_old,
                          double h, int iterations, std::vector<double>& lambda);
  bool implicit_euler_step(World& world, double dt, double tolerance, int max_iterations,
                           VectorX& dv, LinearSolveStats& stats) override;
  bool vbd_sweeps(World& world, const VbdGraph& graph, const Matrix3X& x_n, const Matrix3X& y,
                  double h, int iterations) override;
#if defined(CLOTHLAB_CHOLMOD)
  // The local/global solver's iterations (local_global.cpp): the local step and the right-hand
  // side in the fast layout on the threads, the solve by CHOLMOD. Not in the web module, which
  // has no CHOLMOD: there the integrator's own loop runs.
  bool local_global_iterate(World& world, LocalGlobalSystem& system, int iterations) override;
#endif

  // Which of the world's force effects it summed itself in its last evaluation ("gravity+
  // springs+ buoyancy-"), for tests and for `clothlab bench`.
  std::string plan() const;
  // Springs of those effects it takes through grid stencils (springs.hpp), as last prepared.
  size_t stencil_springs() const;

  // An update of particles [begin, end) after their forces are summed: it may read f and change
  // the state of those particles only. Without `copies`, it reads them in the engine's layout.
  // With `copies`, the copies hold, for those particles, the same x and v as the engine's
  // layout, bit for bit, and the forces just summed, which the update reads there and also
  // writes into the engine's f as it goes (the forces' copy back). With `guard`, it returns
  // whether the new state of those particles is within the guard's bounds (Guard::within);
  // without, true.
  using MoveRange =
      std::function<bool(Index begin, Index end, const Copies* copies, const Guard* guard)>;

 private:
  // The guard's checks a step's one pass takes on (step).
  struct PassChecks {
    // The contacts' records of the step's start (StepStart), sized for the particles: each
    // thread records its own particles' x and v into them as it copies them, before the barrier.
    const std::vector<StepStart*>* starts = nullptr;
    bool end = false;          // check the state after the move too
    bool end_checked = false;  // the pass checked every particle after moving it,
    bool end_within = false;   // and found them all within the guard's bounds
  };

  // Matches forces_ to the world's force effects and asks each fast form whether it takes this
  // evaluation. Whether any does.
  bool prepare(const World& world);
  // The forces at (x, v) into f; then, with `move`, move on ranges that cover every particle
  // once: where the last effect has a fast form, each thread calls it on its own particles,
  // kPassChunk at a time, right after copying their forces back. With `checks`, (x, v) is the
  // state a step starts from: it is checked as it is copied (a bad one throws the guard's error
  // before any particle moves), and the new state as it is moved if checks->end. When every
  // effect has a fast form, all of it is one job of the threads (one wake), a barrier between
  // the copies and the sums; effects without one add passes of their own.
  void pass(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f,
            const MoveRange* move = nullptr, PassChecks* checks = nullptr);

  struct Force : FastForceSlot<double> {
    bool on = false;  // it takes the current evaluation
  };
  std::vector<Force> forces_;
  std::vector<Contact> contacts_;   // the leading post-step effects that ride along in a pass
  std::vector<StepStart*> starts_;  // theirs (PassChecks::starts)
  std::vector<Contact> resident_contacts_;  // every post-step effect of a run of steps
  Copies copies_;
  ResidentOf<double> resident_;   // steps' two copies of the state
  SoA3Matrix xpbd_x_, xpbd_old_;  // x and x_old in the fast layout, for XPBD's projections
  // VBD: the constants of every spring at every vertex, in the sweep's order (vbd.cpp).
  struct VbdSpring {
    Index other;        // the spring's other end
    double ks, kd, l0;  // its constants this step
  };
  std::vector<VbdSpring> vbd_springs_;
  std::shared_ptr<ImplicitSolver> implicit_;  // implicit Euler's arrays (implicit.cpp)
  // The local/global solver's factor and buffers (local_global.cpp), made on its first step.
  std::shared_ptr<LocalGlobalRoom> local_global_;
  std::shared_ptr<FloatRoom> float_room_;  // made on the first step in float
};

// A world's fast engine: what a scene installs as World::backend.
std::unique_ptr<Backend> make_fast_engine();

}  // namespace clothlab::fast
