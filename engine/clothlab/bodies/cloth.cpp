#include "clothlab/bodies/cloth.hpp"

namespace clothlab {

ClothGrid add_cloth(Particles& p, const ClothSpec& spec) {
  const Index n = spec.rows * spec.cols;
  const ClothGrid grid{p.grow(n, spec.mass / static_cast<double>(n)), spec.rows, spec.cols};
  // Column c runs along +x; row r runs down (-y) for a hanging cloth, along +z for a lying one.
  const Vec3 along_row = Vec3::UnitX() * spec.spacing;
  const Vec3 down_rows = (spec.horizontal ? Vec3::UnitZ() : Vec3(-Vec3::UnitY())) * spec.spacing;
  for (Index r = 0; r < grid.rows; ++r) {
    for (Index c = 0; c < grid.cols; ++c) {
      p.x.col(grid.at(r, c)) =
          spec.origin + static_cast<double>(c) * along_row + static_cast<double>(r) * down_rows;
    }
  }
  if (spec.mass_by_area) {
    // The total over 2 (rows - 1)(cols - 1) triangles of equal area, a third of each to a corner.
    const double third = spec.mass / static_cast<double>(6 * (grid.rows - 1) * (grid.cols - 1));
    p.m.segment(grid.first, n).setZero();
    for (const Triangle& t : grid_triangles(grid)) {
      for (const Index i : t)
        p.m[i] += third;
    }
    p.inv_m.segment(grid.first, n) = p.m.segment(grid.first, n).cwiseInverse();
  }
  return grid;
}

std::vector<IndexPair> structural_pairs(Index rows, Index cols) {
  std::vector<IndexPair> pairs;
  for (Index r = 0; r < rows; ++r) {
    for (Index c = 0; c < cols; ++c) {
      const Index i = r * cols + c;
      if (c + 1 < cols) pairs.emplace_back(i, i + 1);     // along the row
      if (r + 1 < rows) pairs.emplace_back(i, i + cols);  // down the column
    }
  }
  return pairs;
}

std::vector<IndexPair> shear_pairs(Index rows, Index cols) {
  std::vector<IndexPair> pairs;
  for (Index r = 0; r + 1 < rows; ++r) {
    for (Index c = 0; c + 1 < cols; ++c) {
      const Index i = r * cols + c;
      pairs.emplace_back(i, i + cols + 1);  // (r,c)-(r+1,c+1)
      pairs.emplace_back(i + 1, i + cols);  // (r,c+1)-(r+1,c)
    }
  }
  return pairs;
}

std::vector<Triangle> grid_triangles(const ClothGrid& g) {
  std::vector<Triangle> triangles;
  triangles.reserve(static_cast<size_t>(2 * (g.rows - 1) * (g.cols - 1)));
  for (Index r = 0; r + 1 < g.rows; ++r) {
    for (Index c = 0; c + 1 < g.cols; ++c) {
      triangles.push_back({g.at(r, c), g.at(r + 1, c), g.at(r, c + 1)});
      triangles.push_back({g.at(r + 1, c), g.at(r + 1, c + 1), g.at(r, c + 1)});
    }
  }
  return triangles;
}

bool named_pins(const ClothGrid& g, std::string_view name, std::vector<Index>& out) {
  const Index last_row = (g.rows - 1) * g.cols;
  if (name == "none") return true;
  if (name == "top-corners") {
    out.insert(out.end(), {0, g.cols - 1});
  } else if (name == "corners") {
    out.insert(out.end(), {0, g.cols - 1, last_row, last_row + g.cols - 1});
  } else if (name == "top-edge") {
    for (Index c = 0; c < g.cols; ++c)
      out.push_back(c);
  } else if (name == "left-edge") {
    for (Index r = 0; r < g.rows; ++r)
      out.push_back(r * g.cols);
  } else {
    return false;
  }
  return true;
}

void pin(Particles& p, Index i) {
  p.inv_m[i] = 0.0;
  p.v.col(i).setZero();
}

}  // namespace clothlab
