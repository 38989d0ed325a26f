#include "clothlab/bodies/solid.hpp"

#include <array>
#include <utility>

namespace clothlab {

SolidLattice add_solid(Particles& p, const SolidSpec& spec) {
  const Index n = spec.nx * spec.ny * spec.nz;
  const SolidLattice lattice{p.grow(n, spec.mass / static_cast<double>(n)), spec.nx, spec.ny,
                             spec.nz};
  // Spacing along each axis: n particles span n - 1 gaps.
  const Vec3 h(spec.size.x() / static_cast<double>(spec.nx - 1),
               spec.size.y() / static_cast<double>(spec.ny - 1),
               spec.size.z() / static_cast<double>(spec.nz - 1));
  for (Index k = 0; k < spec.nz; ++k) {
    for (Index j = 0; j < spec.ny; ++j) {
      for (Index i = 0; i < spec.nx; ++i) {
        const Vec3 ijk(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
        p.x.col(lattice.at(i, j, k)) = spec.corner + ijk.cwiseProduct(h);
      }
    }
  }
  return lattice;
}

std::vector<IndexPair> solid_structural_pairs(Index nx, Index ny, Index nz) {
  const SolidLattice g{0, nx, ny, nz};
  std::vector<IndexPair> pairs;
  for (Index k = 0; k < nz; ++k) {
    for (Index j = 0; j < ny; ++j) {
      for (Index i = 0; i < nx; ++i) {
        const Index a = g.local(i, j, k);
        if (i + 1 < nx) pairs.emplace_back(a, g.local(i + 1, j, k));  // along x
        if (j + 1 < ny) pairs.emplace_back(a, g.local(i, j + 1, k));  // along y
        if (k + 1 < nz) pairs.emplace_back(a, g.local(i, j, k + 1));  // along z
      }
    }
  }
  return pairs;
}

std::vector<IndexPair> solid_face_diagonal_pairs(Index nx, Index ny, Index nz) {
  const SolidLattice g{0, nx, ny, nz};
  std::vector<IndexPair> pairs;
  for (Index k = 0; k < nz; ++k) {
    for (Index j = 0; j < ny; ++j) {
      for (Index i = 0; i < nx; ++i) {
        // The three faces whose lowest corner is (i, j, k), where the lattice has them; both
        // diagonals of each, as the cloth's shear springs cross a cell.
        if (i + 1 < nx && j + 1 < ny) {  // in the x-y plane
          pairs.emplace_back(g.local(i, j, k), g.local(i + 1, j + 1, k));
          pairs.emplace_back(g.local(i + 1, j, k), g.local(i, j + 1, k));
        }
        if (i + 1 < nx && k + 1 < nz) {  // in the x-z plane
          pairs.emplace_back(g.local(i, j, k), g.local(i + 1, j, k + 1));
          pairs.emplace_back(g.local(i + 1, j, k), g.local(i, j, k + 1));
        }
        if (j + 1 < ny && k + 1 < nz) {  // in the y-z plane
          pairs.emplace_back(g.local(i, j, k), g.local(i, j + 1, k + 1));
          pairs.emplace_back(g.local(i, j + 1, k), g.local(i, j, k + 1));
        }
      }
    }
  }
  return pairs;
}

std::vector<IndexPair> solid_body_diagonal_pairs(Index nx, Index ny, Index nz) {
  const SolidLattice g{0, nx, ny, nz};
  std::vector<IndexPair> pairs;
  for (Index k = 0; k + 1 < nz; ++k) {
    for (Index j = 0; j + 1 < ny; ++j) {
      for (Index i = 0; i + 1 < nx; ++i) {
        // Each corner of the cell's bottom (k) layer to the opposite corner of its top (k + 1).
        pairs.emplace_back(g.local(i, j, k), g.local(i + 1, j + 1, k + 1));
        pairs.emplace_back(g.local(i + 1, j, k), g.local(i, j + 1, k + 1));
        pairs.emplace_back(g.local(i, j + 1, k), g.local(i + 1, j, k + 1));
        pairs.emplace_back(g.local(i + 1, j + 1, k), g.local(i, j, k + 1));
      }
    }
  }
  return pairs;
}

std::vector<Triangle> solid_surface_triangles(const SolidLattice& g) {
  const std::array<Index, 3> n = {g.nx, g.ny, g.nz};
  const auto at = [&](const std::array<Index, 3>& c) { return g.at(c[0], c[1], c[2]); };
  std::vector<Triangle> triangles;
  // The faces across axis d, at its low end (side 0) and its high end (side 1). The face's two
  // axes u, w follow d cyclically, so e_u x e_w = e_d: at the high end a square (c, c + u,
  // c + u + w, c + w) winds around +e_d, outward; at the low end u and w swap to wind around -e_d.
  for (size_t d = 0; d < 3; ++d) {
    for (int side = 0; side < 2; ++side) {
      size_t u = (d + 1) % 3, w = (d + 2) % 3;
      if (side == 0) std::swap(u, w);
      std::array<Index, 3> c00{};
      c00[d] = side == 0 ? 0 : n[d] - 1;
      for (c00[u] = 0; c00[u] + 1 < n[u]; ++c00[u]) {
        for (c00[w] = 0; c00[w] + 1 < n[w]; ++c00[w]) {
          std::array<Index, 3> c10 = c00, c11 = c00, c01 = c00;
          ++c10[u];
          ++c11[u], ++c11[w];
          ++c01[w];
          triangles.push_back({at(c00), at(c10), at(c11)});
          triangles.push_back({at(c00), at(c11), at(c01)});
        }
      }
    }
  }
  return triangles;
}

bool named_solid_pins(const SolidLattice& g, std::string_view name, std::vector<Index>& out) {
  if (name == "none") return true;
  if (name != "top-face" && name != "bottom-face") return false;
  const Index j = name == "top-face" ? g.ny - 1 : 0;
  for (Index k = 0; k < g.nz; ++k) {
    for (Index i = 0; i < g.nx; ++i)
      out.push_back(g.local(i, j, k));
  }
  return true;
}

}  // namespace clothlab
