// aerodynamics.hpp: how the fast engine sees a triangle list (aerodynamics.cpp).
#pragma once

#include <array>
#include <vector>

#include "clothlab/core/triangles.hpp"

namespace clothlab::fast {

// A stretch of the triangle list. In a run, the list's triangles k0, k0 + 1, ... alternate
// between `period` phases, and triangle i of phase p (list position k0 + period i + p) has
// corners base[p][0] + i, base[p][1] + i, base[p][2] + i: a grid's two triangles per cell along
// a row. Otherwise its triangles are taken one by one.
struct TriangleGroup {
  size_t k0 = 0, size = 0;  // list positions [k0, k0 + size)
  bool run = false;
  int period = 1;    // phases (1 or 2)
  Index length = 0;  // triangles per phase
  std::array<Triangle, 2> base{};
  // Corner shares in the order a particle receives them in the list: (phase, corner) pairs.
  std::array<std::array<int, 2>, 6> order{};
};

// The triangle list cut into groups, in order, covering every triangle once.
std::vector<TriangleGroup> triangle_groups(const std::vector<Triangle>& triangles);

}  // namespace clothlab::fast
