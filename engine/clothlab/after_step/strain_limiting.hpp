// strain_limiting.hpp: springs that may stretch only so far (lesson 09).
//
// Provot's deformation constraints ("Deformation Constraints in a Mass-Spring Model to Describe
// Rigid Cloth Behavior", 1995). Soft springs let a hanging cloth stretch far more than real
// cloth ever does: the few springs next to a pin carry the weight of everything below them and
// lengthen by 50 % or more ("super-elastic" sag). Stiffer springs would need a far smaller time
// step. Instead, after the integrator has moved the particles, every spring longer than
// (1 + max_strain) l0 is shortened to exactly that length by moving its two ends toward each
// other along the spring; optionally, every spring shorter than (1 - max_compression) l0 is
// lengthened the same way. For a spring from r1 to r2 of length l = |r2 - r1|, e = (r2 - r1)/l:
//
//   target  = (1 + max_strain) l0        if l > (1 + max_strain) l0
//             (1 - max_compression) l0   if l < (1 - max_compression) l0
//   C       = l - target                 how far the spring is past its limit [m]
//   dr1     = +w1 / (w1 + w2) C e        w = 1/m, the inverse masses [1/kg]
//   dr2     = -w2 / (w1 + w2) C e
//
// Splitting C by inverse mass moves the lighter end more, keeps the centre of mass where it was
// (m1 dr1 + m2 dr2 = 0) and leaves a pinned end (w = 0) where it is. Correcting one spring can
// push a neighbour past its limit, so the effect sweeps over every spring again, up to
// `iterations` times, stopping early once a sweep finds nothing (more than rounding) to correct.
//
// Velocities: a particle moved by dr after the step gets v += dr / dt, so the velocity is again
// the rate at which the particle moved during the step. Without it the stretching velocity that
// the correction undid would still be there, and would stretch the spring again next step.
// Equal and opposite momentum changes, (1/w1) dr1 / dt + (1/w2) dr2 / dt = 0: momentum is kept.
#pragma once

#include "clothlab/core/effect.hpp"

namespace clothlab {

class SpringDampers;

struct StrainLimits {
  double max_strain = 0.1;       // longest a spring may be: (1 + max_strain) l0, >= 0
  double max_compression = 1.0;  // shortest: (1 - max_compression) l0, 0 to 1; 1 means no
                                 // limit (no length is below 0)
};

// The moves [m] of a spring's two ends that bring it back within its limits.
struct StrainCorrection {
  Vec3 dr1 = Vec3::Zero();
  Vec3 dr2 = Vec3::Zero();
};

// Exercise ex09.1: the correction of one spring from r1 to r2 [m] with rest length l0 [m] whose
// ends have inverse masses w1, w2 [1/kg] (0: pinned). Within its limits, or when it cannot be
// corrected (both ends pinned, or coincident ends that give no direction), both moves are zero.
StrainCorrection strain_limit_correction(const Vec3& r1, const Vec3& r2, double w1, double w2,
                                         double l0, const StrainLimits& limits);

// Applies strain_limit_correction to every spring of `springs` (the scene's "springs" effect:
// structural, shear, a rope's links, a solid's three families and [[spring]] springs, in the same
// world) after each step.
class StrainLimiting final : public PostStepEffect {
 public:
  StrainLimiting(const SpringDampers& springs, const StrainLimits& limits, int iterations)
      : springs_(springs), limits_(limits), iterations_(iterations) {}
  std::string_view name() const override { return "strain_limit"; }
  void apply(World& world, const StepTime& time) override;

  int iterations() const { return iterations_; }       // most sweeps in one step
  int last_sweeps() const { return last_sweeps_; }     // sweeps the last step took
  long total_sweeps() const { return total_sweeps_; }  // over every step so far
  // A sweep whose largest correction is at most this fraction of a rest length ends the loop:
  // the springs are at their limits up to rounding.
  static constexpr double kTolerance = 1e-9;

 private:
  const SpringDampers& springs_;
  StrainLimits limits_;
  int iterations_;  // most sweeps over the springs in one step
  int last_sweeps_ = 0;
  long total_sweeps_ = 0;
};

}  // namespace clothlab
