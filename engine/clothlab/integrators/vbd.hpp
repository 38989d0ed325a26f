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
//   repeat `iterations` times:
//     for each colour, for each free vertex i of that colour:   x_i += vbd_vertex_step(...)
//   v     = (x - x_n) / h                      implicit Euler's velocity
// then the post-step effects as after any step (World::step): ground, planes and sphere, moving
// pins, plasticity, tearing. A pinned vertex (inv_m = 0) moves by h v_n (a moving pin's velocity)
// and no vertex step moves it; it keeps its velocity.
//
// The initial guess. The paper compares several: the previous positions x_n, this y, y plus the
// previous step's acceleration, and an adaptive blend of the last two. This engine starts from
// y, the minimiser of G without the springs: a cloth at rest or in free fall starts where it
// ends, and one iteration already holds the springs implicitly.
//
// Stopped early, the step is not implicit Euler's. A sweep carries a pin's pull only a vertex or
// two further, so on a large cloth of light particles a few sweeps leave the cloth far from the
// pins falling as if they were not there, and the springs between stretch: the cloth acts much
// softer than its ks. Measured with `clothlab run` on a 64 x 64 cloth (2 cm apart, 1 kg in all,
// ks = 1000 N/m, kd = 0.01 N s/m, gravity, top corners pinned) at 1/60 s for 20 steps: its total
// energy went from -6.17 J to 281 J with 1 iteration, 179 J with 10 and 51 J with 100, where
// local-global (10 iterations) ended at -6.23 J. More iterations or smaller steps bring it back.
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

// method = "vbd": implicit Euler by per-vertex Newton steps, swept colour by colour.
class Vbd final : public Integrator {
 public:
  std::string_view name() const override { return "vbd"; }
  void advance(World& world, double dt) override;
  // The external forces are summed once per step.
  int force_evaluations_per_step() const override { return 1; }
  std::string_view springs_without_dt_limit() const override { return "implicitly"; }

  int iterations = 10;  // sweeps over every vertex per step ([integrator] iterations)

  // The graph as last built: again whenever a spring set's ends or constants change (tearing).
  const VbdGraph& graph() const { return graph_; }
  long graph_builds = 0;  // how often it was built

 private:
  VbdGraph graph_;
  std::vector<const SpringSet*> built_from_;  // the spring sets graph_ was built from
  std::vector<unsigned long> versions_;       // and their versions then
  Matrix3X f_ext_, x_n_, y_;
  std::vector<VertexSpring> springs_;  // the springs of the vertex being stepped
};

}  // namespace clothlab
