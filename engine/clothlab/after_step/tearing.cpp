#include "clothlab/after_step/tearing.hpp"

#include <algorithm>
#include <limits>
#include <set>

#include <fmt/format.h>

#include "clothlab/core/kernel_answer.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

void Tearing::apply(World& world, const StepTime& /*time*/) {
  SpringSet& s = springs_.springs();
  const Matrix3X& x = world.particles.x;
  std::vector<double> strain(s.size());
  std::vector<std::pair<Index, Index>> ends(s.size());
  for (size_t k = 0; k < s.size(); ++k) {
    strain[k] = (x.col(s.j(k)) - x.col(s.i(k))).norm() / s.l0(k) - 1.0;
    ends[k] = {std::min(s.i(k), s.j(k)), std::max(s.i(k), s.j(k))};
  }
  std::vector<size_t> torn = select_tears(strain, ends, tear_strain_, max_tears_);
  if (torn.empty()) return;
  check_tears(torn, s.size());
  // The exercise returns them ascending and once each; make sure of it, so that a slip there
  // cannot leave a chosen spring in the cloth while its triangles go.
  std::sort(torn.begin(), torn.end());
  torn.erase(std::unique(torn.begin(), torn.end()), torn.end());
  tear(world, torn);
}

void check_tears(const std::vector<size_t>& torn, size_t count) {
  for (const size_t k : torn) {
    if (k >= count) {
      throw KernelAnswerError(
          "ex06.2",
          fmt::format("select_tears returned the position {}, but there are {} springs, at "
                      "positions 0 to {}{}",
                      k, count, count - 1,
                      k > std::numeric_limits<size_t>::max() / 2
                          ? " (a negative number turned into a size_t: check what you subtract)"
                          : ""));
    }
  }
}

void Tearing::tear(World& world, const std::vector<size_t>& torn) {
  SpringSet& s = springs_.springs();
  // The torn edges, then every triangle that had one of them as a side.
  std::set<std::pair<Index, Index>> gone;
  for (size_t k : torn)
    gone.insert({std::min(s.i(k), s.j(k)), std::max(s.i(k), s.j(k))});
  s.erase(torn);
  torn_ += static_cast<long>(torn.size());
  const auto has_torn_edge = [&](const Triangle& t) {
    for (int a = 0; a < 3; ++a) {
      const Index p = t[a], q = t[(a + 1) % 3];
      if (gone.count({std::min(p, q), std::max(p, q)}) != 0) return true;
    }
    return false;
  };
  std::erase_if(world.triangles, has_torn_edge);
  for (Aerodynamics* aero : aerodynamics_)
    aero->remove_triangles_if(has_torn_edge);
  // A bending spring (a, c) spans the particle m = (a + c) / 2 between them (two apart along a
  // row, a column or a rope). Once either half, (a, m) or (m, c), has torn, it would hold the
  // two sides of the tear together: it goes too.
  if (bending_) {
    SpringSet& b = bending_->springs();
    std::vector<size_t> spanning;
    for (size_t k = 0; k < b.size(); ++k) {
      const Index a = std::min(b.i(k), b.j(k)), c = std::max(b.i(k), b.j(k));
      if ((a + c) % 2 != 0) continue;
      const Index m = (a + c) / 2;
      if (gone.count({a, m}) != 0 || gone.count({m, c}) != 0) spanning.push_back(k);
    }
    b.erase(spanning);
  }
}

}  // namespace clothlab
