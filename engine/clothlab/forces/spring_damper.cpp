#include "clothlab/forces/spring_damper.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "clothlab/core/world.hpp"

namespace clothlab {

void SpringSet::add(Index a, Index b, double ks_ab, double kd_ab, double l0_ab) {
  if (!(l0_ab >= 0.0))
    throw std::invalid_argument(fmt::format(
        "a spring from particle {} to {} with rest length {} m; expected l0 >= 0", a, b, l0_ab));
  i_.push_back(a);
  j_.push_back(b);
  ks_.push_back(ks_ab);
  kd_.push_back(kd_ab);
  l0_.push_back(l0_ab);
  l_built_.push_back(l0_ab);
  changed();
}

void SpringSet::add_at_rest(Index a, Index b, double ks_ab, double kd_ab, const Matrix3X& x) {
  add(a, b, ks_ab, kd_ab, (x.col(b) - x.col(a)).norm());
}

void SpringSet::erase(const std::vector<size_t>& positions) {
  // One pass: copy every spring not removed down over the gaps the removed ones leave.
  size_t kept = 0, next = 0;
  for (size_t k = 0; k < size(); ++k) {
    if (next < positions.size() && positions[next] == k) {
      ++next;
      continue;
    }
    i_[kept] = i_[k];
    j_[kept] = j_[k];
    ks_[kept] = ks_[k];
    kd_[kept] = kd_[k];
    l0_[kept] = l0_[k];
    l_built_[kept] = l_built_[k];
    ++kept;
  }
  for (auto* column : {&ks_, &kd_, &l0_, &l_built_})
    column->resize(kept);
  i_.resize(kept);
  j_.resize(kept);
  changed();
}

void SpringSet::set_ends(size_t k, Index a, Index b) {
  i_[k] = a;
  j_[k] = b;
  changed();
}

void SpringSet::reverse() {
  for (auto* column : {&ks_, &kd_, &l0_, &l_built_})
    std::reverse(column->begin(), column->end());
  std::reverse(i_.begin(), i_.end());
  std::reverse(j_.begin(), j_.end());
  std::swap(i_, j_);
  changed();
}

void SpringSet::set_ks(size_t k, double value) {
  ks_[k] = value;
  changed();
}

void SpringSet::set_kd(size_t k, double value) {
  kd_[k] = value;
  changed();
}

namespace {
// One counter for every set and both versions: two sets never share a version unless one is a
// copy of the other (and then their ends and constants, or their rest lengths, are the same too).
unsigned long next_change() {
  static std::atomic<unsigned long> changes{0};
  return ++changes;
}
}  // namespace

void SpringSet::changed() {
  version_ = next_change();
}

void SpringSet::rest_changed() {
  rest_version_ = next_change();
}

void add_spring_family(SpringSet& springs, const std::vector<std::pair<Index, Index>>& pairs,
                       Index first, double ks, double kd, const Matrix3X& x) {
  // Sorted by direction b - a, then by a: springs with the same direction and consecutive first
  // ends follow each other, which is what a run is (the order of the pairs matters nowhere else).
  std::vector<std::pair<Index, Index>> sorted = pairs;
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto& p, const auto& q) {
    return std::pair(p.second - p.first, p.first) < std::pair(q.second - q.first, q.first);
  });
  for (const auto& [a, b] : sorted)
    springs.add_at_rest(first + a, first + b, ks, kd, x);
}

const SpringDampers* find_spring_effect(const World& world, std::string_view name) {
  for (const auto& effect : world.force_effects) {
    if (effect->name() == name) return dynamic_cast<const SpringDampers*>(effect.get());
  }
  return nullptr;
}

SpringDampers* find_spring_effect(World& world, std::string_view name) {
  return const_cast<SpringDampers*>(find_spring_effect(std::as_const(world), name));
}

void SpringDampers::add_forces(const Particles& /*p*/, const Matrix3X& x, const Matrix3X& v,
                               Matrix3X& f) const {
  const SpringSet& s = springs_;
  for (size_t k = 0; k < s.size(); ++k) {
    const Index a = s.i(k), b = s.j(k);
    const Vec3 f1 =
        spring_damper_force(x.col(a), x.col(b), v.col(a), v.col(b), s.ks(k), s.kd(k), s.l0(k));
    f.col(a) += f1;  // f2 = -f1: what pulls one end pushes the other
    f.col(b) -= f1;
  }
}

double SpringDampers::potential_energy(const Particles& /*p*/, const Matrix3X& x) const {
  const SpringSet& s = springs_;
  double energy = 0.0;
  for (size_t b = 0; b < s.size(); b += kEnergyBlock) {  // block by block (kEnergyBlock)
    double block = 0.0;
    for (size_t k = b; k < std::min(s.size(), b + kEnergyBlock); ++k)
      block += spring_energy(x.col(s.i(k)), x.col(s.j(k)), s.ks(k), s.l0(k));
    energy += block;
  }
  return energy;
}

SpringJacobian spring_damper_jacobian(const Vec3& r1, const Vec3& r2, double ks, double kd,
                                      double l0) {
  const Vec3 d = r2 - r1;
  const double l = d.norm();
  if (l == 0.0) return {Mat3::Zero(), Mat3::Zero()};  // no direction: no force, no Jacobian
  const Vec3 e = d / l;
  const Mat3 along = e * e.transpose();  // projects onto the spring's direction
  const double across = std::max(0.0, 1.0 - l0 / l);
  return {ks * (along + across * (Mat3::Identity() - along)), kd * along};
}

bool SpringDampers::add_jacobians(const Particles& /*p*/, const Matrix3X& x, const Matrix3X& /*v*/,
                                  ForceJacobians& jacobians) const {
  const SpringSet& s = springs_;
  for (size_t k = 0; k < s.size(); ++k) {
    const SpringJacobian jac =
        spring_damper_jacobian(x.col(s.i(k)), x.col(s.j(k)), s.ks(k), s.kd(k), s.l0(k));
    jacobians.add_pair(s.i(k), s.j(k), jac.dfdx, jac.dfdv);
  }
  return true;
}

}  // namespace clothlab
