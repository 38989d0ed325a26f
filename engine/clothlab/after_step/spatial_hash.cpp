#include "clothlab/after_step/spatial_hash.hpp"

#include <algorithm>
#include <limits>
#include <type_traits>

#include <fmt/format.h>

#include "clothlab/core/kernel_answer.hpp"

namespace clothlab {

void throw_slot_outside(const Cell& c, std::size_t table_size, std::size_t slot) {
  // A negative slot computed on signed integers comes back as a size_t near 2^64.
  const bool negative = slot > std::numeric_limits<std::size_t>::max() / 2;
  throw KernelAnswerError(
      "ex10.1",
      fmt::format("cell_hash(cell ({}, {}, {}), {}) returned the slot {}, but a table of {} slots "
                  "has slots 0 to {}{}",
                  c.ix, c.iy, c.iz, table_size, slot, table_size, table_size - 1,
                  negative ? fmt::format(" ({} as a signed number: compute on std::uint64_t, "
                                         "where nothing is negative)",
                                         static_cast<std::make_signed_t<std::size_t>>(slot))
                           : std::string()));
}

void SpatialHash::build(const Matrix3X& x, double h, double bound) {
  h_ = h;
  ++builds_;
  // clear() keeps the capacity: after the first step no vector here allocates again.
  members_.clear();
  cells_.clear();
  for (Index i = 0; i < x.cols(); ++i) {
    // !(|x| <= bound) also catches a NaN.
    if (!(x.col(i).cwiseAbs().maxCoeff() <= bound)) continue;
    members_.push_back(i);
    cells_.push_back(cell_of(x.col(i), h));
  }
  // About two slots a particle keeps the chance that two occupied cells share a slot low.
  const std::size_t n_slots = 2 * members_.size() + 1;
  starts_.assign(n_slots + 1, 0);
  entries_.resize(members_.size());
  entry_cells_.resize(members_.size());
  // Counting sort: count each slot's particles in starts_[s + 1] ...
  slots_.resize(members_.size());
  for (std::size_t m = 0; m < members_.size(); ++m) {
    slots_[m] = checked_cell_hash(cells_[m], n_slots);
    ++starts_[slots_[m] + 1];
  }
  // ... so that the prefix sum makes starts_[s] the first entry of slot s ...
  for (std::size_t s = 0; s < n_slots; ++s)
    starts_[s + 1] += starts_[s];
  // ... then fill each slot from its start, advancing a cursor kept in starts_[s] itself, which
  // ends up at the start of slot s + 1; one shift puts the starts back.
  for (std::size_t m = 0; m < members_.size(); ++m) {
    const std::size_t e = starts_[slots_[m]]++;
    entries_[e] = members_[m];
    entry_cells_[e] = cells_[m];
  }
  for (std::size_t s = n_slots; s > 0; --s)
    starts_[s] = starts_[s - 1];
  starts_[0] = 0;
}

void SpatialHash::find_pairs(const Matrix3X& x, double radius, std::vector<IndexPair>& out) const {
  out.clear();
  for_each_pair(x, radius, [&](Index i, Index j) { out.emplace_back(i, j); });
  // Within one i the cells come in hash order; sorting makes the list comparable.
  std::sort(out.begin(), out.end());
}

void brute_force_pairs(const Matrix3X& x, double radius, std::vector<IndexPair>& out) {
  out.clear();
  const double r2 = radius * radius;
  for (Index i = 0; i < x.cols(); ++i) {
    for (Index j = i + 1; j < x.cols(); ++j) {
      if ((x.col(j) - x.col(i)).squaredNorm() < r2) out.emplace_back(i, j);
    }
  }
}

}  // namespace clothlab
