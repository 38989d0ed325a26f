#include "clothlab/integrators/xpbd.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <utility>
#include <vector>

#include "clothlab/core/backend.hpp"
#include "clothlab/core/effect.hpp"
#include "clothlab/core/stop.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

int xpbd_colouring(Index particles, const std::vector<Index>& i, const std::vector<Index>& j,
                   std::vector<int>& colour) {
  // used[p]: the colours of the constraints so far at particle p, a bit each, 64 to a word.
  std::vector<std::vector<uint64_t>> used(static_cast<size_t>(particles));
  const auto word = [&](Index p, size_t w) { return w < used[p].size() ? used[p][w] : 0; };
  const auto mark = [&](Index p, size_t w, uint64_t bit) {
    if (used[p].size() <= w) used[p].resize(w + 1, 0);
    used[p][w] |= bit;
  };
  colour.resize(i.size());
  int colours = 0;
  for (size_t k = 0; k < i.size(); ++k) {
    size_t w = 0;
    uint64_t taken = word(i[k], 0) | word(j[k], 0);
    while (taken == ~uint64_t{0}) {
      ++w;
      taken = word(i[k], w) | word(j[k], w);
    }
    const int bit = std::countr_one(taken);  // the first colour free at both ends
    mark(i[k], w, uint64_t{1} << bit);
    mark(j[k], w, uint64_t{1} << bit);
    colour[k] = static_cast<int>(64 * w) + bit;
    colours = std::max(colours, colour[k] + 1);
  }
  return colours;
}

void XpbdConstraints::build(Index particles, const std::vector<const SpringSet*>& families) {
  std::vector<Index> ends_i, ends_j;
  std::vector<std::pair<const SpringSet*, size_t>> from;
  for (const SpringSet* s : families) {
    for (size_t n = 0; n < s->size(); ++n) {
      if (s->ks(n) <= 0.0) continue;  // no stiffness: no constraint (alpha = infinity)
      ends_i.push_back(s->i(n));
      ends_j.push_back(s->j(n));
      from.emplace_back(s, n);
    }
  }
  std::vector<int> colour;
  const int colours = xpbd_colouring(particles, ends_i, ends_j, colour);
  // A counting sort by colour, which keeps the effects' order within each colour.
  colour_start.assign(static_cast<size_t>(colours) + 1, 0);
  for (int q : colour)
    ++colour_start[static_cast<size_t>(q) + 1];
  for (size_t q = 0; q < static_cast<size_t>(colours); ++q)
    colour_start[q + 1] += colour_start[q];
  std::vector<size_t> next(colour_start.begin(), colour_start.end() - 1);
  const size_t m = ends_i.size();
  i.resize(m), j.resize(m), ks.resize(m), kd.resize(m), l0.resize(m), set.resize(m), k.resize(m);
  for (size_t c = 0; c < m; ++c) {
    const size_t to = next[static_cast<size_t>(colour[c])]++;
    i[to] = ends_i[c];
    j[to] = ends_j[c];
    set[to] = from[c].first;
    k[to] = from[c].second;
    ks[to] = set[to]->ks(k[to]);
    kd[to] = set[to]->kd(k[to]);
  }
  refresh_rest_lengths();
}

void XpbdConstraints::refresh_rest_lengths() {
  for (size_t c = 0; c < size(); ++c)
    l0[c] = set[c]->l0(k[c]);
}

void Xpbd::advance(World& world, double dt) {
  Particles& p = world.particles;
  const Index n = p.size();
  const double h = dt / substeps;  // dt_s [s]
  f_ext_.resize(3, n);

  // The constraints: every spring family ("springs", "bending"); every other force effect is
  // an external force. Looked up each step: tearing removes springs between steps.
  // The colouring is made again only when a set's springs change (SpringSet::version).
  std::vector<const SpringSet*> families;
  std::vector<unsigned long> versions;
  for (const auto& effect : world.force_effects) {
    if (const auto* springs = dynamic_cast<const SpringDampers*>(effect.get())) {
      families.push_back(&springs->springs());
      versions.push_back(springs->springs().version());
    }
  }
  if (families != built_from_ || versions != versions_) {
    constraints_.build(n, families);
    built_from_ = families;
    versions_ = versions;
  } else {
    constraints_.refresh_rest_lengths();
  }
  lambda_.resize(constraints_.size());
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

    // The projections, Gauss-Seidel colour by colour: each constraint sees the corrections made
    // before it. The world's backend may take them (the same bits); else this loop does.
    std::fill(lambda_.begin(), lambda_.end(), 0.0);
    if (world.backend && world.backend->xpbd_project(world, constraints_, x_old_, h, iterations,
                                                     keep_lambda, lambda_)) {
      ++backend_substeps;
    } else {
      const XpbdConstraints& cs = constraints_;
      for (int it = 0; it < iterations; ++it) {
        if (it > 0) stop_point();  // a TERM between iterations too
        for (size_t c = 0; c < cs.size(); ++c) {
          const Index i = cs.i[c], j = cs.j[c];
          Vec3 x_i = p.x.col(i), x_j = p.x.col(j);
          const double delta_lambda =
              xpbd_project(x_i, x_j, x_old_.col(i), x_old_.col(j), p.inv_m[i], p.inv_m[j], cs.ks[c],
                           cs.kd[c], cs.l0[c], h, lambda_[c]);
          p.x.col(i) = x_i;
          p.x.col(j) = x_j;
          if (keep_lambda) lambda_[c] += delta_lambda;
        }
      }
    }

    // The velocity the particles moved at over the substep.
    p.v = (p.x - x_old_) / h;
    if (s + 1 < substeps) {
      const StepTime substep = StepTime::of_substep(world.t, dt, s, substeps);
      for (PostStepEffect* contact : contacts)
        contact->apply(world, substep);
    }
  }
}

}  // namespace clothlab
