#include "clothlab/bodies/rope.hpp"

namespace clothlab {

Rope add_rope(Particles& p, const RopeSpec& spec) {
  const Index n = spec.particles;
  const Rope rope{p.grow(n, spec.mass / static_cast<double>(n)), n};
  for (Index k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) / static_cast<double>(n - 1);
    p.x.col(rope.first + k) = (1.0 - s) * spec.start + s * spec.end;
  }
  return rope;
}

std::vector<IndexPair> rope_pairs(Index count) {
  std::vector<IndexPair> pairs;
  for (Index k = 0; k + 1 < count; ++k)
    pairs.emplace_back(k, k + 1);
  return pairs;
}

std::vector<IndexPair> rope_bending_pairs(Index count) {
  std::vector<IndexPair> pairs;
  for (Index k = 0; k + 2 < count; ++k)
    pairs.emplace_back(k, k + 2);
  return pairs;
}

}  // namespace clothlab
