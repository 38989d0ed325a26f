#include "clothlab/forces/bending.hpp"

namespace clothlab {

SpringSet bending_springs(const ClothGrid& grid, double ks, double kd, const Matrix3X& x) {
  SpringSet springs;
  add_spring_family(springs, bending_pairs(grid.rows, grid.cols), grid.first, ks, kd, x);
  return springs;
}

}  // namespace clothlab
