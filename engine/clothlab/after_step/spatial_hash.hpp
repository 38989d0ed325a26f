// spatial_hash.hpp: the broad phase of collision detection, a uniform grid stored in a hash table
// (lesson 10).
//
// Testing every pair of n particles costs n (n - 1) / 2 distance checks: 20 million for a
// 80 x 80 cloth, every step. Yet a particle can only touch particles within `thickness` of it.
// Cut space into cubic cells of edge h >= thickness; a particle at x lies in the cell
//
//   (ix, iy, iz) = (floor(x / h), floor(y / h), floor(z / h))       (exercise ex10.1)
//
// and any particle closer than h to it lies in the same cell or in one of the 26 around it. Space
// is unbounded, so the cells are not stored as a 3D array; their coordinates are hashed into a
// table of fixed size (Teschner et al., "Optimized Spatial Hashing for Collision Detection of
// Deformable Objects", 2003):
//
//   hash(ix, iy, iz) = (ix * 73856093  xor  iy * 19349663  xor  iz * 83492791)  mod  table_size
//
// Two far-apart cells can share a slot of the table, so each entry keeps its cell, and a query
// of cell c takes from c's slot only the particles of cell c. Building costs O(n). Each particle
// then looks at the particles of 14 of the 27 cells around it (each pair of neighbouring cells is
// visited from one side only): O(n) for all pairs when the particles are spread out.
//
// The table is a counting sort, rebuilt every step without allocating: count the particles of
// each slot, turn the counts into starts (a prefix sum), then drop each particle's index into
// its slot's range of `entries`.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/types.hpp"

namespace clothlab {

// The integer coordinates of a cell of the grid.
struct Cell {
  std::int64_t ix = 0, iy = 0, iz = 0;
};

// Exercise ex10.1: the cell of edge h [m] that holds the point x [m], floor(x / h) per coordinate.
// A point on a cell's lower face belongs to that cell: x = 0.5, h = 0.25 is in cell 2.
Cell cell_of(const Vec3& x, double h);

// Exercise ex10.1: the slot of cell c in a table of table_size > 0 slots, by the hash above. The
// products and the xor are taken on 64-bit unsigned integers, which wrap around (a negative
// coordinate is taken as its two's-complement bit pattern), so the result is always in
// [0, table_size).
std::size_t cell_hash(const Cell& c, std::size_t table_size);

// Throws KernelAnswerError (kernel_answer.hpp): cell_hash(c, table_size) gave `slot`, which is
// not below table_size.
[[noreturn]] void throw_slot_outside(const Cell& c, std::size_t table_size, std::size_t slot);

// cell_hash, checked: a slot outside the table would make the hash read and write outside its
// arrays, so the engine takes the exercise's answer only when it is below table_size.
inline std::size_t checked_cell_hash(const Cell& c, std::size_t table_size) {
  const std::size_t slot = cell_hash(c, table_size);
  if (slot >= table_size) [[unlikely]]
    throw_slot_outside(c, table_size, slot);
  return slot;
}

// The offsets (dx, dy, dz) of a cell and of the 13 of its 26 neighbours that come after it,
// ordered by dx, then dy, then dz: the other 13 are met from the other side.
inline constexpr std::array<std::array<std::int64_t, 3>, 14> kHalfShell = {{
    {0, 0, 0},
    {0, 0, 1},
    {0, 1, -1},
    {0, 1, 0},
    {0, 1, 1},
    {1, -1, -1},
    {1, -1, 0},
    {1, -1, 1},
    {1, 0, -1},
    {1, 0, 0},
    {1, 0, 1},
    {1, 1, -1},
    {1, 1, 0},
    {1, 1, 1},
}};

class SpatialHash {
 public:
  // Sorts the particles at positions x [m] into cells of edge h [m]. A particle with a coordinate
  // beyond +-bound [m] (or not finite) is left out: its cell might not fit in 64-bit integers,
  // and the guard stops the run at the end of the step anyway. The table has about two slots a
  // particle; its vectors are reused from build to build, so only the first build allocates.
  void build(const Matrix3X& x, double h, double bound);

  // Calls pair(i, j), once for each pair i < j of particles closer than `radius` [m]
  // (radius <= h), |x_j - x_i| < radius; x must be the positions of the last build.
  template <class F>
  void for_each_pair(const Matrix3X& x, double radius, F&& pair) const;

  // Every pair i < j closer than radius [m], appended to out (cleared first), sorted by i then j.
  void find_pairs(const Matrix3X& x, double radius, std::vector<IndexPair>& out) const;

  double cell_size() const { return h_; }
  std::size_t table_size() const { return starts_.empty() ? 0 : starts_.size() - 1; }
  long builds() const { return builds_; }  // how often build() has run

 private:
  double h_ = 0.0;                   // cell edge [m]
  std::vector<Index> members_;       // the particles in the table (all those within bounds)
  std::vector<Cell> cells_;          // the cell of each member
  std::vector<std::size_t> slots_;   // the slot of each member's cell
  std::vector<std::size_t> starts_;  // slot s holds entries_[starts_[s], starts_[s + 1])
  std::vector<Index> entries_;       // particle indices, grouped by slot
  std::vector<Cell> entry_cells_;    // the cell of each entry
  long builds_ = 0;
};

// The same pairs by testing all n (n - 1) / 2 of them: the slow, obviously right version the
// hash is checked against (and timed against in lesson 10's program). Sorted by i then j.
void brute_force_pairs(const Matrix3X& x, double radius, std::vector<IndexPair>& out);

template <class F>
void SpatialHash::for_each_pair(const Matrix3X& x, double radius, F&& pair) const {
  const std::size_t n_slots = table_size();
  if (n_slots == 0) return;
  const double r2 = radius * radius;
  for (std::size_t m = 0; m < members_.size(); ++m) {
    const Index i = members_[m];
    const Cell c = cells_[m];
    const Vec3 xi = x.col(i);
    // Half of the 27 cells around c: c itself and the 13 that come after it in (dx, dy, dz)
    // order. A pair of particles in two neighbouring cells is then met once, from the cell that
    // comes first, and each particle looks up 14 slots instead of 27.
    for (const std::array<std::int64_t, 3>& d : kHalfShell) {
      const Cell nc{c.ix + d[0], c.iy + d[1], c.iz + d[2]};
      const bool same_cell = d[0] == 0 && d[1] == 0 && d[2] == 0;
      const std::size_t s = checked_cell_hash(nc, n_slots);
      for (std::size_t e = starts_[s]; e < starts_[s + 1]; ++e) {
        const Index j = entries_[e];
        if (same_cell && j <= i) continue;  // within a cell, each pair once, from its lower index
        // The slot also holds the particles of any other cell that hashes to it, maybe one of
        // those visited too: taking only those of cell nc meets each pair once.
        const Cell& cj = entry_cells_[e];
        if (cj.ix != nc.ix || cj.iy != nc.iy || cj.iz != nc.iz) continue;
        if ((x.col(j) - xi).squaredNorm() < r2) pair(std::min(i, j), std::max(i, j));
      }
    }
  }
}

}  // namespace clothlab
