#include "clothlab/integrators/xpbd.hpp"

#include <algorithm>

#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

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

  for (int s = 0; s < substeps; ++s) {
    // External forces at the substep's start (gravity, wind, drag, a game's push, ...).
    f_ext_.setZero();
    ++world.force_evaluations;  // one sum of the external forces a substep (reports)
    for (const auto& effect : world.force_effects) {
      if (!dynamic_cast<const SpringDampers*>(effect.get()))
        effect->add_forces(p, p.x, p.v, f_ext_);
    }
    // The springs' dampers, explicitly: the spring-damper force with ks = 0 is the damper
    // -kd ((v_i - v_j) . e) e alone. Stable while kd (w_i + w_j) dt_s < 2, which small substeps
    // give for any cloth damper (lesson 12).
    for (const SpringSet* set : families) {
      for (size_t k = 0; k < set->size(); ++k) {
        if (set->kd(k) == 0.0) continue;
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
      size_t c = 0;
      for (const SpringSet* set : families) {
        for (size_t k = 0; k < set->size(); ++k, ++c) {
          if (set->ks(k) <= 0.0) continue;  // no stiffness: no constraint (alpha = infinity)
          const Index i = set->i(k), j = set->j(k);
          const double alpha_tilde = 1.0 / (set->ks(k) * h * h);  // alpha / dt_s^2, alpha = 1/ks
          Vec3 x_i = p.x.col(i), x_j = p.x.col(j);
          const double delta_lambda = xpbd_distance_projection(x_i, x_j, p.inv_m[i], p.inv_m[j],
                                                               set->l0(k), alpha_tilde, lambda_[c]);
          p.x.col(i) = x_i;
          p.x.col(j) = x_j;
          if (keep_lambda) lambda_[c] += delta_lambda;
        }
      }
    }

    // The velocity the particles moved at over the substep.
    p.v = (p.x - x_old_) / h;
  }
}

}  // namespace clothlab
