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
// (PostStepEffect::each_substep), told that they close substep s of `substeps`, of dt_s
// (StepTime::of_substep). advance() applies them after substeps 0 to substeps - 2; World::step
// applies the last substep's with the other post-step effects, which see whole steps (tearing,
// plasticity, strain limiting, self-collision, moving pins).
// A pinned particle has w = 0: the prediction moves it by dt_s v only (a moving pin's velocity)
// and no projection moves it.
//
// The order of the projections. Each projection sees the corrections made before it
// (Gauss-Seidel), so the order is part of the method: another order gives another (equally
// valid) result. The constraints are projected colour by colour: a greedy colouring of the
// constraint graph (xpbd_colouring) puts two constraints in the same colour only if they share
// no particle. Within a colour no projection reads what another writes, so their order there
// changes nothing, and a faster engine may project a colour's constraints all at once, on
// several threads (engine/fast/xpbd.cpp), with the same bits as this file's loop, which walks
// them one after the other. On a grid the colours are few (lesson 12): each family of springs
// alternates two or three colours along its rows.
#pragma once

#include <cstdint>
#include <vector>

#include "clothlab/core/integrator.hpp"
#include "clothlab/core/types.hpp"

namespace clothlab {

class SpringSet;

// Exercise ex12.1: one XPBD projection of the distance constraint between particles i and j at
// x_i, x_j [m], with inverse masses w_i, w_j [1/kg] (0: pinned), rest length l0 [m], compliance
// over the step alpha_tilde = alpha / dt^2 [1/kg] (0: rigid) and the multiplier lambda [kg m]
// accumulated so far in this step.
// Moves x_i and x_j by the corrections and returns delta_lambda, which the caller adds to
// lambda. When the constraint cannot move anything (both ends pinned and alpha_tilde = 0, or
// w_i + w_j = 0, or coincident ends that give no direction), it moves nothing and returns 0.
double xpbd_distance_projection(Vec3& x_i, Vec3& x_j, double w_i, double w_j, double l0,
                                double alpha_tilde, double lambda);

// The damper of a spring as XPBD's damping term (Macklin et al. 2016, eq. 26), folded into the
// undamped projection (the exercise's kernel, eq. 18). With g = grad C . (x - x_old), how far
// the substep has stretched the constraint so far [m], eq. 26 reads
//   delta_lambda = (-C - alpha_tilde lambda - gamma g) / ((1 + gamma) (w_i + w_j) + alpha_tilde)
// and, divided through by (1 + gamma), it is eq. 18 with
//   C_d = (C + gamma g) / (1 + gamma)      in place of C,
//   alpha_tilde / (1 + gamma)              in place of alpha_tilde.
// The kernel computes C = l - l0 itself, so it is handed l0_d = l - C_d. Here
// gamma = alpha_tilde beta_tilde / dt_s with beta_tilde = dt_s^2 beta and beta = kd: a distance
// constraint's damping force -beta grad C^T grad C v is the damper -kd ((v_i - v_j) . e) e,
// so gamma = kd / (ks dt_s). Changes alpha_tilde and l0; leaves them when the ends coincide.
inline void xpbd_damp(const Vec3& dx_i, const Vec3& dx_j, const Vec3& d, double gamma,
                      double& alpha_tilde, double& l0) {
  const double l = d.norm();  // [m]
  if (l == 0.0) return;       // no direction: the kernel moves nothing either
  const double C = l - l0;
  const double g = d.dot(dx_i - dx_j) / l;  // grad C . (x - x_old), grad_i C = d / l = -grad_j C
  l0 = l - (C + gamma * g) / (1.0 + gamma);
  alpha_tilde /= 1.0 + gamma;
}

// One projection of a spring (ks > 0, kd, l0) as a damped compliant constraint over a substep
// of h [s], its ends at x_i, x_j now and at old_i, old_j at the substep's start: the exercise's
// kernel, after xpbd_damp when kd > 0. Returns delta_lambda. Both engines call this.
inline double xpbd_project(Vec3& x_i, Vec3& x_j, const Vec3& old_i, const Vec3& old_j, double w_i,
                           double w_j, double ks, double kd, double l0, double h, double lambda) {
  double alpha_tilde = 1.0 / (ks * h * h);  // alpha / dt_s^2, alpha = 1/ks
  if (kd > 0.0) xpbd_damp(x_i - old_i, x_j - old_j, x_i - x_j, kd / (ks * h), alpha_tilde, l0);
  return xpbd_distance_projection(x_i, x_j, w_i, w_j, l0, alpha_tilde, lambda);
}

// The greedy colouring of a constraint graph: constraint k joins particles i[k] and j[k];
// colour[k] is the smallest colour that no constraint before it touching i[k] or j[k] has.
// Two constraints that share a particle never share a colour. Returns the number of colours.
int xpbd_colouring(Index particles, const std::vector<Index>& i, const std::vector<Index>& j,
                   std::vector<int>& colour);

// XPBD's constraints in the order they are projected: colour by colour, and within a colour in
// the order of the spring effects (struct of arrays: constraint c joins i[c] and j[c]).
struct XpbdConstraints {
  std::vector<Index> i, j;
  std::vector<double> ks, kd, l0;
  std::vector<size_t> colour_start;   // colour q is [colour_start[q], colour_start[q + 1])
  std::vector<const SpringSet*> set;  // where constraint c comes from: set[c]'s spring k[c]
  std::vector<size_t> k;

  size_t size() const { return i.size(); }
  int colours() const { return static_cast<int>(colour_start.size()) - 1; }
  // Every spring of `families` with ks > 0 (a spring without stiffness is no constraint).
  void build(Index particles, const std::vector<const SpringSet*>& families);
  // The rest lengths again (plasticity changes them between steps without a new version).
  void refresh_rest_lengths();
};

// method = "xpbd": springs and bending springs as compliant distance constraints.
class Xpbd final : public Integrator {
 public:
  std::string_view name() const override { return "xpbd"; }
  void advance(World& world, double dt) override;
  // The external forces are summed once per substep.
  int force_evaluations_per_step() const override { return substeps; }
  int substeps_per_step() const override { return substeps; }
  std::string_view springs_without_dt_limit() const override { return "as constraints"; }

  int substeps = 10;   // substeps per step ([integrator] substeps)
  int iterations = 1;  // projections of every constraint per substep ([integrator] iterations)
  // false: lambda is forgotten between iterations (kept at 0), as in plain PBD with a stiffness
  // factor; the stiffness then depends on the iterations and the step. For lesson 12's
  // comparison; scenes always keep it.
  bool keep_lambda = true;

  // The constraints as last projected, and how many substeps' projections the world's backend
  // took (the engine room, engine/fast/xpbd.cpp) rather than this file's loop.
  const XpbdConstraints& constraints() const { return constraints_; }
  long backend_substeps = 0;

 private:
  Matrix3X f_ext_, x_old_;
  XpbdConstraints constraints_;
  std::vector<unsigned long> versions_;  // of the spring sets constraints_ was built from
  std::vector<const SpringSet*> built_from_;
  std::vector<double> lambda_;  // one per constraint, in constraints_'s order
};

}  // namespace clothlab
