// xpbd.hpp: position-based dynamics with compliance (XPBD) and small steps (lesson 12).
//
// Macklin, Mueller and Chentanez, "XPBD: Position-Based Simulation of Compliant Constrained
// Dynamics" (2016); Macklin et al., "Small Steps in Physics Simulation" (2019).
//
// A force-based integrator asks springs for forces and moves particles by them; a stiff spring
// then needs a tiny step (lesson 08). XPBD turns each spring into a distance constraint and moves
// the particles to satisfy it, softened by the spring's compliance alpha = 1/ks [m/N]:
//
//   C = |x_i - x_j| - l0,   n = (x_i - x_j) / |x_i - x_j|         (grad_i C = n, grad_j C = -n)
//   alpha_tilde  = alpha / dt^2                                   compliance over the step
//   delta_lambda = (-C - alpha_tilde lambda) / (w_i + w_j + alpha_tilde)
//   x_i += +w_i delta_lambda n,   x_j += -w_j delta_lambda n,   lambda += delta_lambda
//
// lambda [kg m] is the constraint's multiplier, accumulated over the iterations of one step
// (and reset to 0 at the start of each step); -lambda / dt^2 is the spring's tension [N]. With
// alpha = 0 the constraint is rigid: this is the projection of Jakobsen and of plain PBD.
//
// A spring's damper kd [N s/m] is the paper's damping term (its eq. 26), beta = kd:
//   gamma        = alpha_tilde beta_tilde / dt = kd / (ks dt),    beta_tilde = dt^2 beta
//   delta_lambda = (-C - alpha_tilde lambda - gamma grad C . (x - x_old))
//                  / ((1 + gamma) (w_i + w_j) + alpha_tilde)
// which resists the constraint's rate of change over the step, implicitly: stable for any kd.
// (xpbd.cpp folds it into the undamped projection above; kd = 0 leaves that unchanged.)
//
// One step of dt with `substeps` substeps of dt_s = dt / substeps, each (Small Steps):
//   f_ext  = every force effect but the springs, at the substep's start (and the dampers of
//            springs with ks = 0, which are no constraints, as explicit forces)
//   x_old  = x
//   x      = x + dt_s v + dt_s^2 w f_ext                          the prediction x*
//   repeat `iterations` times: project every constraint (above), in order
//   v      = (x - x_old) / dt_s
//   the contacts with fixed solids ([ground], [[plane]], [sphere]), as after a step
// (PostStepEffect::each_substep; World::step applies the last substep's with the other post-step
// effects, which see whole steps: tearing, plasticity, strain limiting, self-collision).
// A pinned particle has w = 0: the prediction moves it by dt_s v only (a moving pin's velocity)
// and no projection moves it.
#pragma once

#include <vector>

#include "clothlab/core/types.hpp"
#include "clothlab/integrators/integrator.hpp"

namespace clothlab {

// Exercise ex12.1: one XPBD projection of the distance constraint between particles i and j at
// x_i, x_j [m], with inverse masses w_i, w_j [1/kg] (0: pinned), rest length l0 [m], compliance
// over the step alpha_tilde = alpha / dt^2 [1/kg] (0: rigid) and the multiplier lambda [kg m]
// accumulated so far in this step.
// Moves x_i and x_j by the corrections and returns delta_lambda, which the caller adds to
// lambda. When the constraint cannot move anything (both ends pinned and alpha_tilde = 0, or
// w_i + w_j = 0, or coincident ends that give no direction), it moves nothing and returns 0.
double xpbd_distance_projection(Vec3& x_i, Vec3& x_j, double w_i, double w_j, double l0,
                                double alpha_tilde, double lambda);

// method = "xpbd": springs and bending springs as compliant distance constraints.
class Xpbd final : public Integrator {
 public:
  std::string_view name() const override { return "xpbd"; }
  void advance(World& world, double dt) override;
  // The external forces are summed once per substep.
  int force_evaluations_per_step() const override { return substeps; }
  std::string_view springs_without_dt_limit() const override { return "as constraints"; }

  int substeps = 10;   // substeps per step ([integrator] substeps)
  int iterations = 1;  // projections of every constraint per substep ([integrator] iterations)
  // false: lambda is forgotten between iterations (kept at 0), as in plain PBD with a stiffness
  // factor; the stiffness then depends on the iterations and the step. For lesson 12's
  // comparison; scenes always keep it.
  bool keep_lambda = true;

 private:
  Matrix3X f_ext_, x_old_;
  std::vector<double> lambda_;  // one per constraint, in the order of the spring effects
};

}  // namespace clothlab
