// Lesson 06, plasticity and tearing: the exercise kernels.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`.
// Tear a sheet on your code with
//   ./build/clothlab-student run lessons/06-plasticity-and-tearing/tearing-sheet.toml
// Every symbol is explained in lessons/06-plasticity-and-tearing/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include <algorithm>
#include <cmath>

#include "clothlab/after_step/plasticity.hpp"
#include "clothlab/after_step/tearing.hpp"
#include "clothlab/core/not_implemented.hpp"

namespace clothlab {

// Exercise ex06.1: the plastic update of one spring's rest length (see plasticity.hpp).
//   strain = (l - l0) / l0; within +-yield_strain nothing changes;
//   otherwise target = l / (1 + yield_strain) (stretched) or l / (1 - yield_strain) (compressed),
//   l0' = l0 + min(1, flow_rate dt) (target - l0), kept within l_built (1 +- max_strain).
// Hints:
//   1. Compare |strain| with the yield strain first: an elastic spring must come back unchanged,
//      bit for bit.
//   2. Move l0 only part of the way to the target: the fraction min(1, flow_rate * dt).
//   3. Clamp last, with std::clamp, to the range around l_built (not around l0).
double plastic_rest_length(double l, double l0, double l_built, const PlasticLimits& limits,
                           double dt) {
  // BEGIN ex06.1: see lessons/06-plasticity-and-tearing/README.md
  CLOTHLAB_TODO("ex06.1", "lessons/06-plasticity-and-tearing/README.md");
  // END ex06.1
}

// Exercise ex06.2: which springs tear this step (see tearing.hpp).
// Hints:
//   1. Collect the positions k with strain[k] > tear_strain.
//   2. If max_tears > 0 and there are more than that, sort them most strained first, equal
//      strains by ends[k] (a std::pair compares lexicographically), and keep the first max_tears.
//   3. Return the kept positions in ascending order: the engine removes them in one pass.
std::vector<size_t> select_tears(const std::vector<double>& strain,
                                 const std::vector<std::pair<Index, Index>>& ends,
                                 double tear_strain, size_t max_tears) {
  // BEGIN ex06.2: see lessons/06-plasticity-and-tearing/README.md
  CLOTHLAB_TODO("ex06.2", "lessons/06-plasticity-and-tearing/README.md");
  // END ex06.2
}

}  // namespace clothlab
