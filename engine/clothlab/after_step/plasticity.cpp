#include "clothlab/after_step/plasticity.hpp"

#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

void Plasticity::apply(World& world, const StepTime& time) {
  SpringSet& s = springs_.springs();
  const Matrix3X& x = world.particles.x;
  for (size_t k = 0; k < s.size(); ++k) {
    const double l = (x.col(s.j(k)) - x.col(s.i(k))).norm();
    s.set_l0(k, plastic_rest_length(l, s.l0(k), s.l_built(k), limits_,
                                    time.h));  // the flow over the span
  }
}

}  // namespace clothlab
