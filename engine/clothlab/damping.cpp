#include "clothlab/damping.hpp"

namespace clothlab {

void Damping::add_forces(const Particles& p, const Matrix3X& /*x*/, const Matrix3X& v,
                         Matrix3X& f) const {
  // f_i = -rate m_i v_i: scale each column of v by its particle's mass.
  f.noalias() -= rate_ * (v * p.m.asDiagonal());
}

}  // namespace clothlab
