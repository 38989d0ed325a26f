#include "clothlab/forces/gravitation.hpp"

#include "clothlab/core/stop.hpp"

namespace clothlab {

void Gravitation::add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& /*v*/,
                             Matrix3X& f) const {
  for (Index i = 0; i < p.size(); ++i) {
    stop_point();  // n^2 / 2 pairs: minutes on a big cloth (core/stop.hpp)
    for (Index j = i + 1; j < p.size(); ++j) {
      const Vec3 f_ij = gravitation_force(x.col(i), p.m[i], x.col(j), p.m[j], G_);
      f.col(i) += f_ij;  // Newton's third law: j feels the same pull, reversed
      f.col(j) -= f_ij;
    }
  }
}

double Gravitation::potential_energy(const Particles& p, const Matrix3X& x) const {
  double energy = 0.0;
  for (Index i = 0; i < p.size(); ++i) {
    stop_point();  // n^2 / 2 pairs: minutes on a big cloth (core/stop.hpp)
    for (Index j = i + 1; j < p.size(); ++j) {
      const double r = (x.col(j) - x.col(i)).norm();
      if (r > 0.0) energy -= G_ * p.m[i] * p.m[j] / r;
    }
  }
  return energy;
}

}  // namespace clothlab
