// stability.hpp: how large a time step a scene can take (lesson 08).
//
// Every explicit integrator has a largest stable time step, and it is set by the stiffest,
// lightest part of the scene. Lesson 08 works it out on the test problem of every stability
// analysis, one damped oscillator,
//   x'' = -w^2 x - beta x',     w^2 = k / m,   beta = c / m,
// on which one step of any of our integrators is a matrix A(dt): (x', v') = A (x, v). Errors
// grow without bound exactly when A has an eigenvalue larger than 1 in modulus (its spectral
// radius rho > 1). With y = dt w and no damping:
//   explicit Euler, midpoint     rho > 1 for every dt: they add energy at every step
//   symplectic Euler, Verlet     stable for y < 2
//   RK4                          stable for y < 2 sqrt 2
//   implicit Euler               stable at every dt
// Damping changes the limits, and not always for the better: symplectic Euler needs
// dt^2 k + 2 dt c < 4 m, position Verlet (whose velocity lags half a step) dt^2 k + 4 dt c < 4 m,
// while explicit Euler and midpoint, unstable without it, become stable for small enough dt
// (explicit Euler dt < c / k up to critical damping: exercise ex08.1, stability_limit.hpp).
// Rather than a formula per case, the advisor computes the eigenvalues of each method's step
// matrix, and asks the exercise's kernel for explicit Euler.
//
// A cloth is many coupled oscillators; its highest angular frequency w_max is the square root
// of the largest eigenvalue of M^-1 K. Gershgorin's theorem bounds it cheaply, without solving
// for eigenvalues: every eigenvalue of a symmetric matrix lies within a row's off-diagonal sum
// of its diagonal entry. On the symmetric M^-1/2 K M^-1/2, in 3x3 blocks,
//   w_max^2 <= max_i  |K_ii| / m_i  +  sum over springs (i, j) of |K_ij| / sqrt(m_i m_j)
// where |.| is a block's largest |eigenvalue| and a pinned j adds nothing off the diagonal.
// The same sum over the damping blocks bounds beta. Both are upper bounds, tight for a single
// spring and within about 1.5 times for a cloth grid. A particle's two row sums belong together:
// a mode that stretches its springs also works their dampers, so each particle's row is one
// oscillator (w_i, beta_i), and the advisor takes the worst of them. (Pairing the highest w
// with the smallest damping anywhere would call explicit Euler unstable on any cloth whose
// dampers sit on its springs.) It reports the time-step limit and how much the stiffest mode
// would grow.
#pragma once

#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "clothlab/core/world.hpp"

namespace clothlab {

// One step of `integrator` on the oscillator x'' = -w^2 x - beta x', as a matrix on the
// integrator's state: (x, v) for every method but position Verlet, whose state is
// (x_n, x_n-1, a_n-1). Each method is written out as the engine steps it.
Eigen::MatrixXd oscillator_step_matrix(std::string_view integrator, double dt, double omega,
                                       double beta);

// The largest |eigenvalue| of a step matrix.
double spectral_radius(const Eigen::MatrixXd& a);

// The largest dt [s] at which `integrator` is stable on the oscillator (w, beta), found from the
// eigenvalues of its step matrix: the first dt, going up from 0, at which the spectral radius
// leaves 1. 0 when it is unstable at every dt, infinity when it is stable at every dt.
double eigenvalue_dt_limit(std::string_view integrator, double omega, double beta);

// The same limit as the advisor takes it: explicit Euler's from the closed form of exercise
// ex08.1 (largest_stable_dt_explicit_euler, with m = 1 kg), every other method's from the
// eigenvalues.
double oscillator_dt_limit(std::string_view integrator, double omega, double beta);

// `x` [s] as text with `digits` significant digits, rounded toward zero, so that the number
// printed is never above x: a printed limit must hold at exactly the value printed.
std::string round_down(double x, int digits = 3);

// A time-step limit as `clothlab validate` prints it: "dt <= 9.55e-05 s" (rounded down),
// "none (unstable at every dt)" or "any".
std::string describe_dt_limit(double dt_limit);

// One particle's Gershgorin row as an oscillator x'' = -w^2 x - beta x'.
struct RowOscillator {
  double omega = 0.0;  // the square root of the row's stiffness sum [rad/s]
  double beta = 0.0;   // the row's damping sum [1/s]
};

// Gershgorin bounds for a world at its current state.
struct StiffnessBounds {
  double omega_max = 0.0;  // >= the highest angular frequency [rad/s]
  double beta_max = 0.0;   // >= the largest damping rate c/m of any mode [1/s]
  double beta_min = 0.0;   // <= the damping rate every particle has ([damping] rate) [1/s]
  // The free particles' rows, those alike merged: for each damping ratio zeta = beta / 2w
  // (to 0.1 %), the highest w that has it, with the ratio's lowest and highest value in the
  // group. A method's limit at a fixed zeta falls as 1 / w, so these hold the worst row.
  std::vector<RowOscillator> rows;
};
StiffnessBounds stiffness_bounds(const World& world);

// What the advisor says about stepping `world` with its integrator at dt for `steps` steps.
struct TimeStepAdvice {
  StiffnessBounds bounds;
  double dt_limit = std::numeric_limits<double>::infinity();  // [s]; 0: unstable at every dt
  double growth = 1.0;  // how much the stiffest mode's amplitude may grow over the run
  std::string warning;  // empty when dt is fine
};
TimeStepAdvice advise_time_step(const World& world, double dt, long steps);

}  // namespace clothlab
