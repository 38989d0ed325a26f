// tearing.hpp: springs that break when stretched too far, and the cloth that tears with them.
//
// Lecture: past a second, larger limit a spring breaks: it is removed for good. A triangle that
// loses one of its edges is removed too, so the air stops pushing on a hole, and so is a bending
// spring that reached across the torn spring. Which springs break
// in a step must not depend on the order they are stored in: otherwise the same cloth would
// tear differently after an unrelated change to how it was built. So the choice is made on the
// springs' strains and their end particles only (exercise ex06.2), and applied all at once.
#pragma once

#include <utility>
#include <vector>

#include "clothlab/core/effect.hpp"

namespace clothlab {

class SpringDampers;
class Aerodynamics;

// Exercise ex06.2: the positions (ascending) of the springs that tear this step. A spring tears
// when its strain (l / l0 - 1) is larger than tear_strain. When max_tears > 0 and more springs
// than that are over the limit, only the max_tears most strained tear; among equal strains the
// spring whose end particles (smaller index first) come first in lexicographic order goes first.
std::vector<size_t> select_tears(const std::vector<double>& strain,
                                 const std::vector<std::pair<Index, Index>>& ends,
                                 double tear_strain, size_t max_tears);

// Throws KernelAnswerError unless every position in `torn` names one of `count` springs (0 to
// count - 1): what select_tears must return for the engine to remove the springs it names.
void check_tears(const std::vector<size_t>& torn, size_t count);

// Tears the springs of `springs` past tear_strain after each step, with the bending springs of
// `bending` (may be null) that span a tear, and the triangles a tear opens in `world.triangles`
// and in each of `aerodynamics`. The effects it is given live in the same world: they outlive it.
class Tearing final : public PostStepEffect {
 public:
  Tearing(SpringDampers& springs, SpringDampers* bending, std::vector<Aerodynamics*> aerodynamics,
          double tear_strain, size_t max_tears)
      : springs_(springs),
        bending_(bending),
        aerodynamics_(std::move(aerodynamics)),
        tear_strain_(tear_strain),
        max_tears_(max_tears) {}
  std::string_view name() const override { return "tearing"; }
  void apply(World& world, const StepTime& time) override;
  // Tears the springs at `positions` (ascending, once each) in `springs`, with what goes with
  // them: what apply() does with the springs select_tears() chose. (A page that reads its scene
  // again tears the new cloth where the old one had torn.)
  void tear(World& world, const std::vector<size_t>& positions);
  long torn() const { return torn_; }  // springs torn so far

 private:
  SpringDampers& springs_;
  SpringDampers* bending_;
  std::vector<Aerodynamics*> aerodynamics_;
  double tear_strain_;  // strain past which a spring breaks
  size_t max_tears_;    // most springs torn in one step (0: no limit)
  long torn_ = 0;
};

}  // namespace clothlab
