#include "clothlab/forces/bending.hpp"

#include <fmt/format.h>

#include "clothlab/core/kernel_answer.hpp"

namespace clothlab {

SpringSet bending_springs(const ClothGrid& grid, double ks, double kd, const Matrix3X& x) {
  const std::vector<IndexPair> pairs = bending_pairs(grid.rows, grid.cols);
  check_bending_pairs(pairs, grid.rows, grid.cols);
  SpringSet springs;
  add_spring_family(springs, pairs, grid.first, ks, kd, x);
  return springs;
}

void check_bending_pairs(const std::vector<IndexPair>& pairs, Index rows, Index cols) {
  const Index n = rows * cols;
  for (const IndexPair& pair : pairs) {
    // Named, not a structured binding: the web build's Clang 14 lets no lambda capture one.
    const Index a = pair.first, b = pair.second;
    const auto fail = [&](const std::string& why) {
      throw KernelAnswerError(
          "ex04.1", fmt::format("bending_pairs({}, {}) returned the pair ({}, {}): {}", rows, cols,
                                a, b, why));
    };
    for (const Index i : {a, b}) {
      if (i < 0 || i >= n) {
        fail(fmt::format("{} is not a particle of a {} x {} grid, whose particles are 0 to {}", i,
                         rows, cols, n - 1));
      }
    }
    if (a == b) fail("a spring from a particle to itself has no length and no direction");
  }
}

}  // namespace clothlab
