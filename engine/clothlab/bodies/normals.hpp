// normals.hpp: per-vertex normals of a body's surface, for shading and for the mesh files.
#pragma once

#include <vector>

#include "clothlab/core/triangles.hpp"
#include "clothlab/core/types.hpp"

namespace clothlab {

// Per-vertex normals: the area-weighted average of the normals of the triangles around each
// vertex (the cross product's length is twice the area, so plain sums weight by area). A vertex
// in no triangle gets a zero normal.
Matrix3X vertex_normals(const Matrix3X& x, const std::vector<Triangle>& triangles);
// The same into `normals`, resized to 3 x N: no allocation when it has that size already.
void vertex_normals(const Matrix3X& x, const std::vector<Triangle>& triangles, Matrix3X& normals);

}  // namespace clothlab
