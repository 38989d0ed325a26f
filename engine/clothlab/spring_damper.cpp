#include "clothlab/spring_damper.hpp"

#include <algorithm>

#include "clothlab/world.hpp"

namespace clothlab {

void SpringSet::add(Index a, Index b, double ks_ab, double kd_ab, double l0_ab, const Matrix3X& x) {
  i.push_back(a);
  j.push_back(b);
  ks.push_back(ks_ab);
  kd.push_back(kd_ab);
  l0.push_back(l0_ab >= 0.0 ? l0_ab : (x.col(b) - x.col(a)).norm());
  l_built.push_back(l0.back());
}

void SpringSet::erase(const std::vector<size_t>& positions) {
  // One pass: copy every spring not removed down over the gaps the removed ones leave.
  size_t kept = 0, next = 0;
  for (size_t k = 0; k < size(); ++k) {
    if (next < positions.size() && positions[next] == k) {
      ++next;
      continue;
    }
    i[kept] = i[k];
    j[kept] = j[k];
    ks[kept] = ks[k];
    kd[kept] = kd[k];
    l0[kept] = l0[k];
    l_built[kept] = l_built[k];
    ++kept;
  }
  for (auto* column : {&ks, &kd, &l0, &l_built})
    column->resize(kept);
  i.resize(kept);
  j.resize(kept);
}

void add_spring_family(SpringSet& springs, const std::vector<std::pair<Index, Index>>& pairs,
                       Index first, double ks, double kd, const Matrix3X& x) {
  for (const auto& [a, b] : pairs)
    springs.add(first + a, first + b, ks, kd, -1.0, x);
}

SpringDampers* find_spring_effect(World& world, std::string_view name) {
  for (auto& effect : world.force_effects) {
    if (effect->name() == name) return dynamic_cast<SpringDampers*>(effect.get());
  }
  return nullptr;
}

void SpringDampers::add_forces(const Particles& /*p*/, const Matrix3X& x, const Matrix3X& v,
                               Matrix3X& f) const {
  const SpringSet& s = springs_;
  for (size_t k = 0; k < s.size(); ++k) {
    const Index a = s.i[k], b = s.j[k];
    const Vec3 f1 =
        spring_damper_force(x.col(a), x.col(b), v.col(a), v.col(b), s.ks[k], s.kd[k], s.l0[k]);
    f.col(a) += f1;  // f2 = -f1: what pulls one end pushes the other
    f.col(b) -= f1;
  }
}

double SpringDampers::potential_energy(const Particles& /*p*/, const Matrix3X& x) const {
  const SpringSet& s = springs_;
  double energy = 0.0;
  for (size_t k = 0; k < s.size(); ++k) {
    energy += spring_energy(x.col(s.i[k]), x.col(s.j[k]), s.ks[k], s.l0[k]);
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
        spring_damper_jacobian(x.col(s.i[k]), x.col(s.j[k]), s.ks[k], s.kd[k], s.l0[k]);
    jacobians.add_pair(s.i[k], s.j[k], jac.dfdx, jac.dfdv);
  }
  return true;
}

}  // namespace clothlab
