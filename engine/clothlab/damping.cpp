#include "clothlab/damping.hpp"

namespace clothlab {

void Damping::add_forces(const Particles& p, const Matrix3X& /*x*/, const Matrix3X& v,
                         Matrix3X& f) const {
  // f_i = -rate m_i v_i: scale each column of v by its particle's mass.
  f.noalias() -= rate_ * (v * p.m.asDiagonal());
}

void Damping::add_forces_soa(const Particles& p, const SoA3& /*x*/, const SoA3& v, SoA3& f,
                             Index begin, Index end) const {
  // The same products as add_forces's Eigen expression, rate (v m), component by component.
  const double* __restrict m = p.m.data();
  for (int c = 0; c < 3; ++c) {
    double* __restrict fc = f.row(c).data();
    const double* __restrict vc = v.row(c).data();
    for (Index i = begin; i < end; ++i)
      fc[i] -= rate_ * (vc[i] * m[i]);
  }
}

bool Damping::add_jacobians(const Particles& p, const Matrix3X& /*x*/, const Matrix3X& /*v*/,
                            ForceJacobians& jacobians) const {
  for (Index i = 0; i < p.size(); ++i)
    jacobians.add_self(i, Mat3::Zero(), -rate_ * p.m[i] * Mat3::Identity());
  return true;
}

}  // namespace clothlab
