#include "clothlab/integrators/local_global.hpp"

#include <atomic>
#include <stdexcept>

#include "clothlab/core/backend.hpp"
#include "clothlab/core/stop.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

namespace {

// The spring families of the world, in the order of its force effects.
std::vector<const SpringSet*> spring_families(const World& world) {
  std::vector<const SpringSet*> families;
  for (const auto& effect : world.force_effects) {
    if (const auto* springs = dynamic_cast<const SpringDampers*>(effect.get()))
      families.push_back(&springs->springs());
  }
  return families;
}

}  // namespace

bool LocalGlobal::matrix_still_fits(const World& world, double dt) const {
  const Particles& p = world.particles;
  if (factorizations_ == 0 || dt != h_ || p.size() != m_.size() || p.m != m_) return false;
  for (Index i = 0; i < p.size(); ++i) {
    if ((p.inv_m[i] == 0.0) != (system_.unknown[i] < 0)) return false;  // pinned or unpinned since
  }
  // The same families, each at the version it had: no spring torn, no ks or kd changed.
  if (spring_families(world) != families_) return false;
  for (size_t k = 0; k < families_.size(); ++k) {
    if (families_[k]->version() != versions_[k]) return false;
  }
  return true;
}

void LocalGlobal::factor(const World& world, double dt) {
  const Particles& p = world.particles;
  const Index n = p.size();
  const double h = dt;
  h_ = dt;
  m_ = p.m;
  families_ = spring_families(world);
  versions_.clear();
  for (const SpringSet* set : families_)
    versions_.push_back(set->version());

  // The unknowns: the particles that are not pinned.
  system_.unknown.assign(n, -1);
  system_.particle.clear();
  for (Index i = 0; i < n; ++i) {
    if (p.inv_m[i] == 0.0) continue;
    system_.unknown[i] = static_cast<Index>(system_.particle.size());
    system_.particle.push_back(i);
  }

  // A = M + h C + h^2 L on the unknowns: a spring adds c = h kd + h^2 ks to the diagonal of each
  // free end and -c between two free ends (its row of L x is ks (x_i - x_j), of C x kd (x_i -
  // x_j)).
  std::vector<Eigen::Triplet<double>> triplets;
  for (const Index i : system_.particle)
    triplets.emplace_back(system_.unknown[i], system_.unknown[i], p.m[i]);
  size_t springs = 0;
  for (const SpringSet* set : families_) {
    springs += set->size();
    for (size_t k = 0; k < set->size(); ++k) {
      const Index a = system_.unknown[set->i(k)], b = system_.unknown[set->j(k)];
      const double c = h * set->kd(k) + h * h * set->ks(k);
      if (a >= 0) triplets.emplace_back(a, a, c);
      if (b >= 0) triplets.emplace_back(b, b, c);
      if (a >= 0 && b >= 0) {
        triplets.emplace_back(a, b, -c);
        triplets.emplace_back(b, a, -c);
      }
    }
  }
  const auto unknowns = static_cast<Index>(system_.particle.size());
  Eigen::SparseMatrix<double>& a = system_.a;
  a.resize(unknowns, unknowns);
  a.setFromTriplets(triplets.begin(), triplets.end());  // adds up repeated entries
  // A number no other system has had in this process, so that a backend holding the factor of
  // an earlier system (another integrator's, at the same address, say) sees this one as new.
  static std::atomic<long> systems_built{0};
  system_.version = ++systems_built;
  llt_.compute(a);
  // Every mass is positive and every c >= 0, so A is symmetric positive definite: a failure
  // here is a bug, not a scene to reject.
  if (llt_.info() != Eigen::Success)
    throw std::runtime_error("local-global: the matrix M + h C + h^2 L could not be factored");
  ++factorizations_;
  // The springs in one list, for the world's backend.
  system_.i.clear();
  system_.j.clear();
  system_.push.clear();
  for (const SpringSet* set : families_) {
    for (size_t k = 0; k < set->size(); ++k) {
      system_.i.push_back(set->i(k));
      system_.j.push_back(set->j(k));
      system_.push.push_back(h * h * set->ks(k));
    }
  }

  // A spring keeps its d between steps, for when its ends coincide; until its first local step
  // that is l0 along x. Kept over a refactor that leaves the springs as they were (a new dt).
  if (system_.d.cols() != static_cast<Index>(springs)) {
    system_.d.resize(3, static_cast<Index>(springs));
    Index s = 0;
    for (const SpringSet* set : families_) {
      for (size_t k = 0; k < set->size(); ++k, ++s)
        system_.d.col(s) = Vec3(set->l0(k), 0.0, 0.0);
    }
  }
}

void LocalGlobal::advance(World& world, double dt) {
  Particles& p = world.particles;
  const Index n = p.size();
  const double h = dt;
  if (!matrix_still_fits(world, dt)) factor(world, dt);

  // f_ext: every force effect but the springs, once, at the step's start.
  f_ext_.setZero(3, n);
  ++world.force_evaluations;
  for (const auto& effect : world.force_effects) {
    if (!dynamic_cast<const SpringDampers*>(effect.get())) effect->add_forces(p, p.x, p.v, f_ext_);
  }

  // Pinned particles move by h v to where their pins take them. The free ones start from the
  // prediction y + h^2 M^-1 f_ext, the minimiser of g without the springs.
  x_n_ = p.x;
  for (Index i = 0; i < n; ++i)
    p.x.col(i) += h * p.v.col(i) + (h * h * p.inv_m[i]) * f_ext_.col(i);

  // The part of the right-hand side no iteration changes: M y + h^2 f_ext + h C x_n, and for a
  // spring to a pinned particle j, its column of A times x_j, moved to the right: (h kd + h^2 ks)
  // x_j'.
  const auto unknowns = static_cast<Index>(system_.particle.size());
  system_.b_fixed.resize(unknowns, 3);
  for (Index r = 0; r < unknowns; ++r) {
    const Index i = system_.particle[r];
    const Vec3 y = x_n_.col(i) + h * p.v.col(i);
    system_.b_fixed.row(r) = (p.m[i] * y + h * h * f_ext_.col(i)).transpose();
  }
  for (const SpringSet* set : families_) {
    for (size_t k = 0; k < set->size(); ++k) {
      const Index i = set->i(k), j = set->j(k), a = system_.unknown[i], b = system_.unknown[j];
      const Vec3 damper = h * set->kd(k) * (x_n_.col(i) - x_n_.col(j));  // h C x_n
      const double c = h * set->kd(k) + h * h * set->ks(k);
      if (a >= 0) {
        system_.b_fixed.row(a) += damper.transpose();
        if (b < 0) system_.b_fixed.row(a) += c * p.x.col(j).transpose();  // x_j' of a pinned end
      }
      if (b >= 0) {
        system_.b_fixed.row(b) -= damper.transpose();
        if (a < 0) system_.b_fixed.row(b) += c * p.x.col(i).transpose();
      }
    }
  }

  // The world's backend may take the iterations (core/backend.hpp); else this loop does.
  bool taken = false;
  if (world.backend) {
    system_.l0.clear();
    for (const SpringSet* set : families_) {
      for (size_t k = 0; k < set->size(); ++k)
        system_.l0.push_back(set->l0(k));  // plasticity changes them between steps
    }
    taken = world.backend->local_global_iterate(world, system_, iterations);
    if (taken) ++backend_steps;
  }
  for (int it = 0; it < iterations && !taken; ++it) {
    stop_point();  // many iterations of a big cloth can take minutes (core/stop.hpp)
    // Local step: each spring's d, the nearest vector of length l0 to x_i - x_j.
    Index s = 0;
    for (const SpringSet* set : families_) {
      for (size_t k = 0; k < set->size(); ++k, ++s) {
        const Vec3 previous = system_.d.col(s);
        system_.d.col(s) =
            local_step_projection(p.x.col(set->i(k)), p.x.col(set->j(k)), set->l0(k), previous);
      }
    }
    // Global step: A x = b_fixed + h^2 J d, each spring pushing ks d into i's row, -ks d into j's.
    b_ = system_.b_fixed;
    s = 0;
    for (const SpringSet* set : families_) {
      for (size_t k = 0; k < set->size(); ++k, ++s) {
        const Vec3 push = (h * h * set->ks(k)) * system_.d.col(s);
        const Index a = system_.unknown[set->i(k)], b = system_.unknown[set->j(k)];
        if (a >= 0) b_.row(a) += push.transpose();
        if (b >= 0) b_.row(b) -= push.transpose();
      }
    }
    x_ = llt_.solve(b_);
    for (Index r = 0; r < unknowns; ++r)
      p.x.col(system_.particle[r]) = x_.row(r).transpose();
  }

  // Implicit Euler's velocity: v' = (x' - x_n) / h. A pinned particle keeps its pin's velocity.
  for (const Index i : system_.particle)
    p.v.col(i) = (p.x.col(i) - x_n_.col(i)) / h;
}

}  // namespace clothlab
