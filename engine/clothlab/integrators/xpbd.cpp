#include "clothlab/integrators/xpbd.hpp"

#include <algorithm>
#include <vector>

#include "clothlab/core/effect.hpp"
#include "clothlab/core/stop.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

namespace {

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
void damp(const Vec3& dx_i, const Vec3& dx_j, const Vec3& d, double gamma, double& alpha_tilde,
          double& l0) {
  const double l = d.norm();  // [m]
  if (l == 0.0) return;       // no direction: the kernel moves nothing either
  const double C = l - l0;
  const double g = d.dot(dx_i - dx_j) / l;  // grad C . (x - x_old), grad_i C = d / l = -grad_j C
  l0 = l - (C + gamma * g) / (1.0 + gamma);
  alpha_tilde /= 1.0 + gamma;
}

}  // namespace

void Xpbd::advance(World& world, double dt) {
  Particles& p = world.particles;
  const Index n = p.size();
  const double h = dt / substeps;  // dt_s [s]
  f_ext_.resize(3, n);

  // The constraints: every spring family ("springs", "bending"); every other force effect is
  // an external force. Looked up each step: tearing removes springs between steps.
  std::vector<const SpringSet*> families;
  size_t constraints = 0;
  for (const auto& effect : world.force_effects) {
    if (const auto* springs = dynamic_cast<const SpringDampers*>(effect.get())) {
      families.push_back(&springs->springs());
      constraints += springs->springs().size();
    }
  }
  lambda_.resize(constraints);
  // The contacts with fixed solids ([ground], [[plane]], [sphere]), which meet the cloth in every
  // substep (PostStepEffect::each_substep): here after each substep but the last, whose
  // contacts World::step applies with the other post-step effects.
  std::vector<PostStepEffect*> contacts;
  for (const auto& effect : world.post_step_effects) {
    if (effect->each_substep()) contacts.push_back(effect.get());
  }

  for (int s = 0; s < substeps; ++s) {
    stop_point();  // a step of many substeps can take minutes (core/stop.hpp)
    if (s > 0) {
      for (PostStepEffect* contact : contacts)
        contact->before_step(world);  // the substep's start, as World::step does for the step's
    }
    // External forces at the substep's start (gravity, wind, drag, a game's push, ...).
    f_ext_.setZero();
    ++world.force_evaluations;  // one sum of the external forces a substep (reports)
    for (const auto& effect : world.force_effects) {
      if (!dynamic_cast<const SpringDampers*>(effect.get()))
        effect->add_forces(p, p.x, p.v, f_ext_);
    }
    // A damper without a spring (ks = 0) is no constraint: it acts as an explicit force, the
    // spring-damper force with ks = 0, -kd ((v_i - v_j) . e) e. Stable while
    // kd (w_i + w_j) dt_s < 2. Every other damper is in the projection below.
    for (const SpringSet* set : families) {
      for (size_t k = 0; k < set->size(); ++k) {
        if (set->kd(k) == 0.0 || set->ks(k) > 0.0) continue;
        const Index i = set->i(k), j = set->j(k);
        const Vec3 f = spring_damper_force(p.x.col(i), p.x.col(j), p.v.col(i), p.v.col(j), 0.0,
                                           set->kd(k), set->l0(k));
        f_ext_.col(i) += f;
        f_ext_.col(j) -= f;
      }
    }

    // The prediction x* = x + dt_s v + dt_s^2 w f_ext; a pinned particle (w = 0) keeps its
    // velocity, which is 0 unless a moving pin drives it.
    x_old_ = p.x;
    for (Index i = 0; i < n; ++i)
      p.x.col(i) += h * p.v.col(i) + (h * h * p.inv_m[i]) * f_ext_.col(i);

    // The projections, Gauss-Seidel: each constraint sees the corrections made before it.
    std::fill(lambda_.begin(), lambda_.end(), 0.0);
    for (int it = 0; it < iterations; ++it) {
      stop_point();
      size_t c = 0;
      for (const SpringSet* set : families) {
        for (size_t k = 0; k < set->size(); ++k, ++c) {
          if (set->ks(k) <= 0.0) continue;  // no stiffness: no constraint (alpha = infinity)
          const Index i = set->i(k), j = set->j(k);
          Vec3 x_i = p.x.col(i), x_j = p.x.col(j);
          double alpha_tilde = 1.0 / (set->ks(k) * h * h);  // alpha / dt_s^2, alpha = 1/ks
          double l0 = set->l0(k);
          if (set->kd(k) > 0.0) {
            damp(x_i - x_old_.col(i), x_j - x_old_.col(j), x_i - x_j, set->kd(k) / (set->ks(k) * h),
                 alpha_tilde, l0);
          }
          const double delta_lambda = xpbd_distance_projection(x_i, x_j, p.inv_m[i], p.inv_m[j], l0,
                                                               alpha_tilde, lambda_[c]);
          p.x.col(i) = x_i;
          p.x.col(j) = x_j;
          if (keep_lambda) lambda_[c] += delta_lambda;
        }
      }
    }

    // The velocity the particles moved at over the substep.
    p.v = (p.x - x_old_) / h;
    if (s + 1 < substeps) {
      for (PostStepEffect* contact : contacts)
        contact->apply(world, h);
    }
  }
}

}  // namespace clothlab
