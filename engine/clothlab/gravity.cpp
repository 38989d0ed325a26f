#include "clothlab/gravity.hpp"

namespace clothlab {

void UniformGravity::add_forces(const Particles& p, const Matrix3X& /*x*/, const Matrix3X& /*v*/,
                                Matrix3X& f) const {
  for (Index i = 0; i < p.size(); ++i)
    f.col(i) += gravity_force(p.m[i], g_);
}

void UniformGravity::add_forces_soa(const Particles& p, const SoA3& /*x*/, const SoA3& /*v*/,
                                    SoA3& f, Index begin, Index end) const {
  double* __restrict fx = f.row(0).data();
  double* __restrict fy = f.row(1).data();
  double* __restrict fz = f.row(2).data();
  const double* __restrict m = p.m.data();
  for (Index i = begin; i < end; ++i) {
    const Vec3 fg = gravity_force(m[i], g_);
    fx[i] += fg.x();
    fy[i] += fg.y();
    fz[i] += fg.z();
  }
}

double UniformGravity::potential_energy(const Particles& p, const Matrix3X& x) const {
  // -sum_i m_i (g . x_i) = -g . (sum_i m_i x_i)
  return -g_.dot(x * p.m);
}

double UniformGravity::energy_scale(const Particles& p, const Matrix3X& /*x*/, double size) const {
  return p.m.sum() * g_.norm() * size;
}

}  // namespace clothlab
