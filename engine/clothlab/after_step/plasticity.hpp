// plasticity.hpp: springs that stay bent when pushed too far (lesson 06).
//
// Lecture: past an elastic limit a material deforms for good. For a spring this means its rest
// length l0 changes. With strain = (l - l0) / l0:
//
//   |strain| <= yield_strain   elastic: nothing changes, the spring springs back;
//   |strain| >  yield_strain   plastic: l0 flows toward the rest length at which the strain
//                              would be exactly the yield strain,
//                                target = l / (1 + yield_strain)   when stretched,
//                                target = l / (1 - yield_strain)   when compressed,
//                              covering the fraction min(1, flow_rate dt) of the way each step,
//                              and never further than max_strain from the length it was built
//                              with: l_built (1 - max_strain) <= l0 <= l_built (1 + max_strain).
//
// target lies between l0 and l, so l0 never overshoots the current length, and |l - l0| only
// shrinks: plastic flow takes energy out of the spring, never puts it in.
#pragma once

#include "clothlab/core/effect.hpp"

namespace clothlab {

class SpringDampers;

struct PlasticLimits {
  double yield_strain = 0.1;  // elastic limit, 0 to 1 (0.1: 10 % stretch)
  double flow_rate = 10.0;    // [1/s] how fast l0 flows toward its target
  double max_strain = 0.5;    // largest permanent change of l0, 0 to 1 (0.5: 50 %)
};

// Exercise ex06.1: the new rest length [m] of a spring of current length l [m], rest length l0 [m]
// and built length l_built [m], after a step of dt [s].
double plastic_rest_length(double l, double l0, double l_built, const PlasticLimits& limits,
                           double dt);

// Applies plastic_rest_length to every spring of `springs` (the scene's "springs" effect, in the
// same world) after each step.
class Plasticity final : public PostStepEffect {
 public:
  Plasticity(SpringDampers& springs, const PlasticLimits& limits)
      : springs_(springs), limits_(limits) {}
  std::string_view name() const override { return "plasticity"; }
  void apply(World& world, const StepTime& time) override;

 private:
  SpringDampers& springs_;
  PlasticLimits limits_;
};

}  // namespace clothlab
