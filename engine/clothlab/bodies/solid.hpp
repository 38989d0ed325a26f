// solid.hpp: a soft solid, a 3D lattice of particles joined by spring-dampers (lesson 09).
//
// Lecture, "Ropes & Solids": the particles and spring-dampers that make a cloth make a rope
// (a chain) and a soft solid (a lattice) just as well. A lattice of nx x ny x nz particles
// fills a box; particle (i, j, k) sits at corner + (i hx, j hy, k hz), with the spacings
// hx = size.x / (nx - 1), ... One cell of the lattice is a small box of 8 particles, corner
// (i, j, k) of the cell numbered i + 2 j + 4 k (y up, z going back):
//
//          6 ------- 7           structural:     the 12 edges of the cell          (length h)
//         /|        /|           face diagonal:  2 across each of its 6 faces      (h sqrt 2)
//        2 ------- 3 |           body diagonal:  4 through its centre, corner to
//        | 4 ------|- 5                          opposite corner                   (h sqrt 3)
//        |/        |/
//        0 ------- 1             12 + 12 + 4 = 28 = every pair of the 8 corners (8 * 7 / 2).
//
// Edges alone would let a cell shear flat like a cardboard box with its ends open; the face
// diagonals keep each face square and the body diagonals keep the cell from folding through
// itself. Neighbouring cells share edges and faces, so each spring is built once, by the lowest
// cell it belongs to.
#pragma once

#include <string_view>
#include <vector>

#include "clothlab/bodies/cloth.hpp"

namespace clothlab {

struct SolidLattice {
  Index first = 0;  // index of particle (0, 0, 0)
  Index nx = 0, ny = 0, nz = 0;
  // Particle (i, j, k): i along x, j along y (up), k along z.
  Index at(Index i, Index j, Index k) const { return first + local(i, j, k); }
  Index local(Index i, Index j, Index k) const { return i + nx * (j + ny * k); }
  Index size() const { return nx * ny * nz; }
};

struct SolidSpec {
  Index nx = 2, ny = 2, nz = 2;     // particles along x, y and z (at least 2 each)
  Vec3 corner = Vec3::Zero();       // position of particle (0, 0, 0), the lowest corner [m]
  Vec3 size = Vec3(1.0, 1.0, 1.0);  // edge lengths of the box along x, y, z [m], all > 0
  double mass = 1.0;                // total mass [kg], shared equally by the particles
};

// Appends the lattice's particles, at rest, and returns where they are.
SolidLattice add_solid(Particles& p, const SolidSpec& spec);

// The pairs of lattice-local indices joined by each spring family; for nx x ny x nz particles:
//   structural     (nx-1) ny nz + nx (ny-1) nz + nx ny (nz-1)
//   face diagonal  2 [(nx-1)(ny-1) nz + (nx-1) ny (nz-1) + nx (ny-1)(nz-1)]
//   body diagonal  4 (nx-1)(ny-1)(nz-1)
std::vector<IndexPair> solid_structural_pairs(Index nx, Index ny, Index nz);
std::vector<IndexPair> solid_face_diagonal_pairs(Index nx, Index ny, Index nz);
std::vector<IndexPair> solid_body_diagonal_pairs(Index nx, Index ny, Index nz);

// The outside of the box as triangles, two per square of each of its six faces, wound so that
// their normals point out of the solid. They are what the viewer and mesh files draw.
std::vector<Triangle> solid_surface_triangles(const SolidLattice& lattice);

// Lattice-local indices of a named set of particles: "top-face" (j = ny - 1), "bottom-face"
// (j = 0), "none". Returns false if the name is not one of these.
bool named_solid_pins(const SolidLattice& lattice, std::string_view name, std::vector<Index>& out);

}  // namespace clothlab
