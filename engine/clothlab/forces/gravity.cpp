#include "clothlab/forces/gravity.hpp"

namespace clothlab {

void UniformGravity::add_forces(const Particles& p, const Matrix3X& /*x*/, const Matrix3X& /*v*/,
                                Matrix3X& f) const {
  for (Index i = 0; i < p.size(); ++i)
    f.col(i) += gravity_force(p.m[i], g_);
}

double UniformGravity::potential_energy(const Particles& p, const Matrix3X& x) const {
  // -sum_i m_i (g . x_i) = -g . (sum_i m_i x_i)
  return -g_.dot(x * p.m);
}

double UniformGravity::energy_scale(const Particles& p, const Matrix3X& /*x*/, double size) const {
  return p.m.sum() * g_.norm() * size;
}

}  // namespace clothlab
