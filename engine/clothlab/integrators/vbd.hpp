// vbd.hpp: Vertex Block Descent (lesson 14), implicit Euler one vertex at a time.
//
// Chen, Liu, Yang and Yuksel, "Vertex Block Descent", ACM Transactions on Graphics 43(4)
// (SIGGRAPH 2024).
//
// Implicit Euler's new positions minimise G(x) = 1/(2 h^2) |x - y|_M^2 + E(x) (lesson 13). The
// local/global solver of lesson 13 splits G by springs and solves one linear system for all the
// particles at once. VBD splits it by vertices and solves none: each vertex in turn takes one
// Newton step on G with its neighbours held still (vbd_vertex.hpp: the 3 x 3 block of its inertia
// and the springs at it), and a sweep over every vertex is one iteration. The sweeps converge to
// G's minimiser, the implicit Euler step, and the step may end after any of them: each vertex has
// then been brought toward balance with its inertia and its neighbours, a usable state that more
// sweeps make more exact. The springs' stiffness sets no limit on the step: a stiff spring only
// makes its vertices' blocks stiffer.
//
// One step of dt = h:
//   f_ext = every force effect but the springs, at the step's start (gravity, wind, drag, a
//           game's push, ...): explicit, as in XPBD and the local/global solver
//   y     = x_n + h v_n + h^2 M^-1 f_ext       where inertia and the external forces carry x
//   x     = y                                  the initial guess: inertia and f_ext, no springs
//                                              (initial_guess = "adaptive": see below)
//   repeat `iterations` times:
//     for each colour, for each free vertex i of that colour:   x_i += vbd_vertex_step(...)
//   v     = (x - x_n) / h                      implicit Euler's velocity
// then the post-step effects as after any step (World::step): ground, planes and sphere, moving
// pins, plasticity, tearing. A pinned vertex (inv_m = 0) moves by h v_n (a moving pin's velocity)
// and no vertex step moves it; it keeps its velocity.
//
// The initial guess. The paper compares several: the previous positions x_n, this y, y plus the
// previous step's acceleration, and an adaptive blend of the last two. This engine starts from
// y by default ([integrator] initial_guess = "inertia"), the minimiser of G without the springs:
// a cloth in free fall starts where it ends, and one iteration already holds the springs
// implicitly. But a cloth that hangs, held up by its springs, does not accelerate, and y drops
// each of its vertices by h^2 g all the same: the sweeps must then lift the whole cloth back,
// through springs that carry the pins' pull a vertex or two per sweep.
//
// initial_guess = "adaptive" is the paper's answer: x = x_n + h v_n + h^2 a g/|g|, with a the
// acceleration each vertex had along gravity in the last step, (v_n - v_n-1) . g/|g| / h,
// clamped to [0, |g|]. A vertex that fell freely last step is guessed falling, one held up is
// not dropped. Without a last step (the first) a is taken as 0, where the paper's code takes y.
// Only the guess changes: y, in G, still carries every external force.
//
// Stopped early, the step is not implicit Euler's, and it can gain energy: this is the method, not
// a flaw of this code. The vertex force and Hessian are G_i's derivatives (checked by finite
// differences in tests/engine/vbd.cpp). In the run measured below, 20 steps of 1, 10 and 100
// iterations end at 291 J, 189 J and 60.5 J; without dampers (kd = 0) at 291 J, 189 J and 60.4 J;
// with the vertices swept in index order instead of by colour at 288 J, 188 J and 60.2 J; without
// the clamp on a compressed spring's Hessian (as the paper's reference code has it) worse, at
// 303 J, 261 J and 60340 J; and with the sweeps converged (1000 iterations) the step loses energy
// as implicit Euler does. The cause is Gauss-Seidel far from converged: here m/h^2 = 0.88 N/m per
// vertex against ks = 1000 N/m, so a vertex step follows its neighbours and barely its inertia, and
// a sweep carries a pin's pull only a vertex or two further. From y the cloth below the top rows
// falls as if it were not pinned, and the springs between stretch, their energy bought from
// nothing. Measured with `clothlab run` on a 64 x 64 cloth (2 cm apart, its top row at y = 1 m,
// 1 kg in all, ks = 1000 N/m, kd = 0.01 N s/m, gravity, top corners pinned; the scene of the test
// "a hanging cloth stepped with few iterations ...") at 1/60 s, total energy [J], starting at
// 3.63 J (a blank: not measured):
//
//   iterations                         1       10      100     1000
//   20 steps, initial_guess "inertia"  291     189     60.5    3.59
//   20 steps, "adaptive"               3.61    3.58    4.26
//   3 s, "inertia"                     876585  146     34.4
//   3 s, "adaptive"                    21289
//
// The adaptive guess holds the hanging cloth while it hangs, but once its lower part has begun
// to fall it guesses it falling, and over 3 s one iteration runs away from it too. (The guard
// stops a run whose energy rises past 1e4 times the scene's energy scale, core/guard.hpp, and
// the scale grows with the energy gravity has released: neither run reaches it.)
//
// Short of many more sweeps, what brings the step back is a better-conditioned G: a smaller
// step raises m/h^2 as 1/h^2. With one iteration over 3 s, 4 steps a frame (h = 1/240 s) end at
// 3155 J from "inertia" and 6.31 J from "adaptive", 16 steps a frame at 3.72 J and 4.18 J. The
// paper's Chebyshev acceleration of the sweeps (its reference code, rho = 0.95) cut 100
// iterations from "inertia" to 8.0 J over 20 steps, but 10 iterations only to 139 J, and with
// rho = 0.99 it diverged (2519 J); it is not offered here.
//
// The colouring. Within a sweep each vertex step sees the positions its neighbours have just
// been given (Gauss-Seidel), so the order is part of the method. The vertices are coloured so
// that no two joined by a spring share a colour (vbd_colouring, greedy), and swept colour by
// colour: within a colour no vertex step reads a position another writes, so their order there
// changes nothing, and a faster engine may take a colour's vertices all at once. On a cloth grid
// with structural and shear springs the colours are four, a 2 x 2 pattern; bending springs, two
// apart, need more.
#pragma once

#include <vector>

#include "clothlab/core/integrator.hpp"
#include "clothlab/core/types.hpp"
#include "clothlab/integrators/vbd_vertex.hpp"

namespace clothlab {

struct Particles;
class SpringSet;

// The springs at each vertex and the vertices colour by colour: what a sweep walks.
struct VbdGraph {
  // Vertex i's springs are entries [start[i], start[i + 1]) of `other`, `set` and `k`: each is
  // spring k of *set, whose other end is `other`. A spring is listed at both its ends.
  std::vector<size_t> start;
  std::vector<Index> other;
  std::vector<const SpringSet*> set;
  std::vector<size_t> k;
  std::vector<int> colour;           // each vertex's colour
  std::vector<Index> order;          // the vertices colour by colour, ascending within a colour
  std::vector<size_t> colour_start;  // colour q is order[colour_start[q] .. colour_start[q + 1])

  int colours() const { return static_cast<int>(colour_start.size()) - 1; }
  // From every spring of `families` over `particles` vertices.
  void build(Index particles, const std::vector<const SpringSet*>& families);
};

// The greedy colouring of a graph given by its adjacency (vertex i's neighbours are
// neighbour[start[i]] .. neighbour[start[i + 1] - 1]): vertex by vertex in index order, each
// takes the smallest colour none of its neighbours coloured before it has. Two neighbours never
// share a colour, and no vertex needs more than its count of neighbours + 1. Writes colour[i] for
// every vertex and returns the number of colours.
int vbd_colouring(const std::vector<size_t>& start, const std::vector<Index>& neighbour,
                  std::vector<int>& colour);

// Where a step's iterations start (the initial guess above).
enum class VbdInitialGuess {
  inertia,   // y, where inertia and the external forces carry each vertex
  adaptive,  // x_n + h v_n + h^2 a g/|g|, a the last step's acceleration along g in [0, |g|]
};

// method = "vbd": implicit Euler by per-vertex Newton steps, swept colour by colour.
class Vbd final : public Integrator {
 public:
  std::string_view name() const override { return "vbd"; }
  void advance(World& world, double dt) override;
  // The external forces are summed once per step.
  int force_evaluations_per_step() const override { return 1; }
  std::string_view springs_without_dt_limit() const override { return "implicitly"; }
  std::string iterations_that_may_stop_short() const override;

  int iterations = 10;     // sweeps over every vertex per step ([integrator] iterations)
  long backend_steps = 0;  // steps whose sweeps the world's backend took (tests/fast/)
  // [integrator] initial_guess = "inertia" or "adaptive"
  VbdInitialGuess initial_guess = VbdInitialGuess::inertia;

  // The graph as last built: again whenever a spring set's ends or constants change (tearing).
  const VbdGraph& graph() const { return graph_; }
  long graph_builds = 0;  // how often it was built

 private:
  VbdGraph graph_;
  std::vector<const SpringSet*> built_from_;  // the spring sets graph_ was built from
  std::vector<unsigned long> versions_;       // and their versions then
  // Sets p.x to the adaptive guess from x_n_, v_n (p.v) and the last step's v_previous_.
  void adaptive_guess(Particles& p, const Vec3& g, double h);

  Matrix3X f_ext_, x_n_, y_;
  Matrix3X v_previous_;  // the velocities the last step began with (the adaptive guess)
  std::vector<VertexSpring> springs_;  // the springs of the vertex being stepped
};

}  // namespace clothlab
