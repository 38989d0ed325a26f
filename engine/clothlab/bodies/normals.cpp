#include "clothlab/bodies/normals.hpp"

namespace clothlab {

Matrix3X vertex_normals(const Matrix3X& x, const std::vector<Triangle>& triangles) {
  Matrix3X normals;
  vertex_normals(x, triangles, normals);
  return normals;
}

void vertex_normals(const Matrix3X& x, const std::vector<Triangle>& triangles, Matrix3X& normals) {
  normals.setZero(3, x.cols());
  for (const Triangle& t : triangles) {
    const Vec3 n_star = (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0]));
    for (Index i : t)
      normals.col(i) += n_star;
  }
  for (Index i = 0; i < normals.cols(); ++i) {
    const double length = normals.col(i).norm();
    if (length > 0.0) normals.col(i) /= length;
  }
}

}  // namespace clothlab
