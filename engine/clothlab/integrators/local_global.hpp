// local_global.hpp: fast mass-spring simulation by a local/global solver (lesson 13).
//
// Liu, Bargteil, O'Brien and Kavan, "Fast Simulation of Mass-Spring Systems", ACM Transactions
// on Graphics 32(6) (SIGGRAPH Asia 2013).
//
// Implicit Euler is a minimisation (lesson 08 took one linearised step of it instead): with
// y = x_n + h v_n the place inertia alone would carry the particles, the new positions minimise
//
//   g(x) = 1/(2 h^2) (x - y)^T M (x - y) + E(x) - f_ext^T x
//
// whose stationary point is M (x - y) / h^2 = f(x) + f_ext, the implicit Euler step. A spring's
// energy ks/2 (|x_i - x_j| - l0)^2 is the smallest of ks/2 |(x_i - x_j) - d|^2 over the vectors d
// of length l0: the nearest such d points along x_i - x_j. So g is the minimum over one d per
// spring of a function that is quadratic in x. Alternate:
//
//   local step:   each spring's d = l0 (x_i - x_j) / |x_i - x_j|   (x fixed; exercise ex13.1)
//   global step:  (M + h^2 L) x = M y + h^2 J d + h^2 f_ext       (d fixed; one linear solve)
//
// with L = sum ks A A^T and J = sum ks A S^T (A: the spring's +1 at i, -1 at j; S picks its d):
// row i of L x - J d is sum over i's springs of ks ((x_i - x_j) - d). Neither step can raise g,
// and `iterations` of them converge to the implicit Euler step. The matrix depends on the
// masses, the ks, which particles the springs join, the pins and h, never on x or l0: it is
// factored once (Eigen's sparse Cholesky) and each global step is two triangular solves, the
// same factor for x, y and z.
//
// Choices of this engine (lesson 13 says why):
//   - the springs' dampers are implicit and isotropic: the damping force on i from spring (i, j)
//     is -kd (v_i - v_j), a Rayleigh-like term whose energy 1/(2h) (x - x_n)^T C (x - x_n) adds
//     h C to the matrix and h C x_n to the right-hand side (C = sum kd A A^T, constant too). Along
//     the spring it is lecture 02's damper; across it, it also slows the pair's relative turning;
//   - every other force effect (gravity, wind, drag, a game's push) is f_ext, taken once at the
//     start of the step;
//   - a pinned particle (inv_m = 0) is not an unknown: it moves by h v (a moving pin's velocity)
//     and its springs push its new place into the right-hand side of its free neighbours' rows.
#pragma once

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <vector>

#include "clothlab/core/integrator.hpp"
#include "clothlab/core/types.hpp"

namespace clothlab {

class SpringSet;

// Exercise ex13.1: the local step for one spring from x_j to x_i [m] with rest length l0 [m]: the
// vector d [m] of length l0 nearest to x_i - x_j, that is l0 (x_i - x_j) / |x_i - x_j|. When the
// ends coincide every d of length l0 is equally near: return d_previous (the spring's d from its
// last local step), never NaN.
Vec3 local_step_projection(const Vec3& x_i, const Vec3& x_j, double l0, const Vec3& d_previous);

// The global step's system as LocalGlobal last built it, for the world's backend
// (core/backend.hpp): the matrix, the unknowns, and the springs in one list (the order of the
// spring families, then of each set).
struct LocalGlobalSystem {
  Eigen::SparseMatrix<double> a;  // M + h C + h^2 L on the free rows (lower and upper halves)
  long version = 0;               // moves each time `a` is built again
  std::vector<Index> unknown;     // particle -> row of the system, -1: pinned
  std::vector<Index> particle;    // row of the system -> particle
  std::vector<Index> i, j;        // each spring's ends
  std::vector<double> l0;         // [m] each spring's rest length, read again each step
  std::vector<double> push;       // [1/s^2 ...] h^2 ks of each spring, as the readable loop has it
  Matrix3X d;                     // [m] each spring's d (kept between steps)
  // [..] The right-hand side's part no iteration changes: one row per unknown, one column per axis.
  Eigen::Matrix<double, Eigen::Dynamic, 3> b_fixed;
};

// method = "local-global": implicit Euler by Liu et al.'s local/global iterations.
class LocalGlobal final : public Integrator {
 public:
  std::string_view name() const override { return "local-global"; }
  void advance(World& world, double dt) override;
  // The external forces are summed once per step.
  int force_evaluations_per_step() const override { return 1; }
  std::string_view springs_without_dt_limit() const override { return "implicitly"; }

  int iterations = 10;  // local and global steps per time step ([integrator] iterations)

  // How often the matrix was factored: once per scene and dt, again when dt, a stiffness, a
  // damper, a mass, a pin or the spring set changes (tearing), never for a rest length.
  long factorizations() const { return factorizations_; }
  // The global step's system as last built (for tests).
  const LocalGlobalSystem& system() const { return system_; }
  // Steps whose iterations the world's backend took (Backend::local_global_iterate).
  long backend_steps = 0;

 private:
  // What the factored matrix was built from; a step that finds any of it changed refactors.
  bool matrix_still_fits(const World& world, double dt) const;
  void factor(const World& world, double dt);

  long factorizations_ = 0;
  double h_ = 0.0;                          // [s] the dt of the factored matrix
  std::vector<const SpringSet*> families_;  // "springs", "bending": every spring is in it
  std::vector<unsigned long> versions_;     // each family's version() when factored
  VectorX m_;                               // [kg] the masses when factored
  LocalGlobalSystem system_;                // the matrix, the unknowns, the springs, d and b_fixed
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt_;  // M + h C + h^2 L on the free rows
  Matrix3X f_ext_;  // [N] the external forces at the step's start
  Matrix3X x_n_;    // [m] the positions the step starts from
  // The global step's right-hand side and its solution: one row per unknown particle, one column
  // per axis.
  Eigen::Matrix<double, Eigen::Dynamic, 3> b_, x_;
};

}  // namespace clothlab
