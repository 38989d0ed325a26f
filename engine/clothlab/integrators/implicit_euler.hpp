// implicit_euler.hpp: implicit (backward) Euler for stiff cloth, after Baraff and Witkin,
// "Large Steps in Cloth Simulation" (SIGGRAPH 1998).
//
// Explicit methods take the forces at the start of the step (or at trial states inside it).
// Stiff springs change their force a lot over one step, and an explicit method that ignores
// this overshoots, further each step, until it explodes. Backward Euler takes the forces at
// the END of the step instead:
//   v' = v + dt M^-1 f(x', v'),   x' = x + dt v'.
// That is an equation in the unknown v'. Linearise f once about the start of the step,
//   f(x', v') ~ f0 + K (x' - x) + D (v' - v),   K = df/dx,  D = df/dv,
// put x' - x = dt v' and solve for dv = v' - v:
//   (M - dt D - dt^2 K) dv = dt (f0 + dt K v).
// With the spring Jacobians of spring_damper.hpp, -K and -D are symmetric positive
// semidefinite, so the matrix on the left is symmetric positive definite: Eigen's conjugate
// gradient solver (with a diagonal preconditioner) solves it, to a relative residual
// `tolerance` in at most `max_iterations` iterations, both set in the scene's [integrator].
// Conjugate gradients need only products with the matrix, converge in a few dozen iterations
// on cloth, and start from the previous step's dv; a direct solver (Eigen's SimplicialLDLT)
// would factor a matrix that changes every step.
//
// The method is unconditionally stable for a linear spring (its energy factor per step is
// 1 / (1 + (dt w)^2) < 1) and first order accurate. It damps: energy leaves faster the larger
// the step, which is the price of stability. Effects without Jacobians (gravity, wind, drag)
// enter through f0 only. A pinned particle's row is left out (its dv is 0).
#pragma once

#include <Eigen/SparseCore>
#include <utility>
#include <vector>

#include "clothlab/core/effect.hpp"
#include "clothlab/core/integrator.hpp"
#include "clothlab/core/types.hpp"

namespace clothlab {

// What the linear solves of a run cost, for `clothlab run --stats` and the benchmark.
struct LinearSolveStats {
  long solves = 0;                // one per step
  long iterations = 0;            // conjugate-gradient iterations over all solves
  long max_iterations = 0;        // the most one solve took
  long unconverged = 0;           // solves that stopped at max_iterations above the tolerance
  double worst_error = 0.0;       // the largest relative residual a solve ended with
  double assembly_seconds = 0.0;  // [s] wall time computing f0, the Jacobians and filling A, b
  double solve_seconds = 0.0;     // [s] wall time in conjugate gradients
};

class ImplicitEuler final : public Integrator {
 public:
  std::string_view name() const override { return "implicit-euler"; }
  void advance(World& world, double dt) override;
  int force_evaluations_per_step() const override { return 1; }

  double tolerance = 1e-6;   // relative residual |A dv - b| / |b| at which a solve stops
  int max_iterations = 500;  // iterations after which a solve stops anyway

  const LinearSolveStats& stats() const { return stats_; }
  // How many steps the world's backend took whole (Backend::implicit_euler_step); the others
  // ran the code below.
  long backend_steps = 0;

  // One 3x3 block of A = M - dt D - dt^2 K at block row i, block column j.
  struct Block {
    Index i, j;
    Mat3 value;
  };

 private:
  // Builds a_'s sparsity pattern for the blocks of this step and where each block's values go.
  void build_pattern(const Particles& p);

  LinearSolveStats stats_;
  VectorX last_dv_;  // the previous step's solution: where the next solve starts

  // The matrix keeps its pattern from step to step while the springs and pins stay the same:
  // the blocks are then refilled in place, with no allocation and no sorting.
  std::vector<Block> blocks_;
  std::vector<std::pair<Index, Index>> pattern_;  // (i, j) of every block, in blocks_ order
  std::vector<bool> pinned_;                      // inv_m == 0, when the pattern was built
  std::vector<Index> block_offsets_;              // where column c of block k starts in a_,
                                                  // at 3 k + c; -1 for a pinned block
  Eigen::SparseMatrix<double> a_;
};

}  // namespace clothlab
