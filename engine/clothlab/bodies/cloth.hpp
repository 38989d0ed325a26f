// cloth.hpp: building a rectangular cloth out of particles, springs and triangles.
//
// A cloth of rows x cols particles, `spacing` apart, numbered row by row:
//
//     (0,0) -- (0,1) -- (0,2)        structural springs: along rows and columns   (--, |)
//       |    X   |    X   |          shear springs: both diagonals of each cell    (X)
//     (1,0) -- (1,1) -- (1,2)        triangles: two per cell, for aerodynamics
//
// Particle (r, c) of a grid has index first + r * cols + c in the world's arrays.
#pragma once

#include <string_view>
#include <utility>
#include <vector>

#include "clothlab/core/particles.hpp"
#include "clothlab/core/triangles.hpp"

namespace clothlab {

using IndexPair = std::pair<Index, Index>;

struct ClothGrid {
  Index first = 0;  // index of particle (0, 0)
  Index rows = 0;
  Index cols = 0;
  Index at(Index r, Index c) const { return first + r * cols + c; }
  Index size() const { return rows * cols; }
};

struct ClothSpec {
  Index rows = 2, cols = 2;    // particles along each side (at least 2 x 2)
  double spacing = 0.1;        // rest distance between neighbours [m]
  Vec3 origin = Vec3::Zero();  // position of particle (0, 0) [m]
  bool horizontal = false;     // false: hangs in the x-y plane, rows going down (-y);
                               // true: lies in the x-z plane, rows going along +z
  double mass = 1.0;           // total mass [kg], shared equally by the particles,
  bool mass_by_area = false;   // or, if true, in proportion to the area each stands for
};

// Appends the cloth's particles, at rest, and returns where they are. Masses by area: each
// triangle (grid_triangles) gives a third of its mass to each corner, as the air gives each a
// third of its force (lesson 03). A particle inside the grid touches six triangles and gets a
// cell's mass; one on the rim three, half of that; a corner one or two (the cells' diagonals run
// from (r, c + 1) to (r + 1, c)), a sixth or a third.

ClothGrid add_cloth(Particles& p, const ClothSpec& spec);

// The pairs of grid-local indices (r * cols + c) joined by each spring family.
std::vector<IndexPair> structural_pairs(Index rows, Index cols);  // (r,c)-(r,c+1), (r,c)-(r+1,c)
std::vector<IndexPair> shear_pairs(Index rows, Index cols);  // (r,c)-(r+1,c+1), (r,c+1)-(r+1,c)

// Exercise ex04.1: the bending (flexion) pairs of a rows x cols grid, particles two apart along
// rows and along columns: (r,c)-(r,c+2) and (r,c)-(r+2,c), as grid-local indices r * cols + c.
std::vector<IndexPair> bending_pairs(Index rows, Index cols);

// Two triangles per cell, (r,c) (r+1,c) (r,c+1) and (r+1,c) (r+1,c+1) (r,c+1).
std::vector<Triangle> grid_triangles(const ClothGrid& grid);

// Grid-local indices of a named set of particles: "top-corners", "corners", "top-edge",
// "left-edge", "none". Returns false if the name is not one of these.
bool named_pins(const ClothGrid& grid, std::string_view name, std::vector<Index>& out);

// Makes particle i immovable: no force can accelerate it (1/m = 0) and it is at rest.
void pin(Particles& p, Index i);

}  // namespace clothlab
