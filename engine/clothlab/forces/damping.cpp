#include "clothlab/forces/damping.hpp"

namespace clothlab {

void Damping::add_forces(const Particles& p, const Matrix3X& /*x*/, const Matrix3X& v,
                         Matrix3X& f) const {
  // f_i = -rate m_i v_i: scale each column of v by its particle's mass.
  f.noalias() -= rate_ * (v * p.m.asDiagonal());
}

bool Damping::add_jacobians(const Particles& p, const Matrix3X& /*x*/, const Matrix3X& /*v*/,
                            ForceJacobians& jacobians) const {
  for (Index i = 0; i < p.size(); ++i)
    jacobians.add_self(i, Mat3::Zero(), -rate_ * p.m[i] * Mat3::Identity());
  return true;
}

}  // namespace clothlab
