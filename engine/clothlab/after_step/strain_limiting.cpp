#include "clothlab/after_step/strain_limiting.hpp"

#include "clothlab/core/stop.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

void StrainLimiting::apply(World& world, const StepTime& time) {
  last_sweeps_ = 0;
  const SpringSet& s = springs_.springs();
  Particles& p = world.particles;
  const double inv_dt = 1.0 / time.h;  // [1/s], over the span the effect closes (a whole step)
  for (int sweep = 0; sweep < iterations_; ++sweep) {
    stop_point();  // many sweeps of a big cloth can take minutes (core/stop.hpp)
    // Gauss-Seidel: each spring sees the corrections of the springs before it in this sweep.
    bool corrected = false;  // some spring was past its limit by more than rounding
    for (size_t k = 0; k < s.size(); ++k) {
      const Index i = s.i(k), j = s.j(k);
      const StrainCorrection c =
          strain_limit_correction(p.x.col(i), p.x.col(j), p.inv_m[i], p.inv_m[j], s.l0(k), limits_);
      // dr1 - dr2 = C e, whatever the split, so |dr1 - dr2| = |C| is how far the spring was past
      // its limit [m]. Most springs are within it, C = 0, and cost nothing more.
      const double excess = (c.dr1 - c.dr2).norm();
      if (excess == 0.0) continue;
      corrected = corrected || excess > kTolerance * s.l0(k);
      p.x.col(i) += c.dr1;
      p.x.col(j) += c.dr2;
      // v += dr / dt: the velocity stays the particle's displacement over the step.
      p.v.col(i) += c.dr1 * inv_dt;
      p.v.col(j) += c.dr2 * inv_dt;
    }
    ++last_sweeps_;
    if (!corrected) break;
  }
  total_sweeps_ += last_sweeps_;
}

}  // namespace clothlab
