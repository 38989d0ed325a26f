// incidence.hpp: which spring ends meet at each row of a system, grouped by row: the layout of a
// sparse matrix's compressed rows. The engine room's implicit Euler (implicit.cpp) and
// local/global solver (local_global.cpp) walk it to gather each particle's springs without
// writing to another particle's row, so that rows can be split over the threads.
#pragma once

#include <cstddef>
#include <vector>

#include "clothlab/core/types.hpp"

namespace clothlab::fast {

// For springs s = 0 .. i.size() - 1 with ends i[s] and j[s], and row_of(particle) the row of a
// particle (or -1 for none: a pinned particle in local/global), the ends 2 s (at i[s]) and
// 2 s + 1 (at j[s]) grouped by row, in spring order: row r's are ends[start[r] .. start[r + 1]).
template <class RowOf>
void group_ends_by_row(const std::vector<Index>& i, const std::vector<Index>& j, Index rows,
                       RowOf row_of, std::vector<Index>& start, std::vector<Index>& ends) {
  const size_t springs = i.size();
  start.assign(static_cast<size_t>(rows) + 1, 0);
  for (size_t s = 0; s < springs; ++s) {
    for (const Index end : {i[s], j[s]}) {
      const Index r = row_of(end);
      if (r >= 0) ++start[static_cast<size_t>(r) + 1];
    }
  }
  for (size_t r = 0; r < static_cast<size_t>(rows); ++r)
    start[r + 1] += start[r];
  ends.assign(static_cast<size_t>(start.back()), 0);
  std::vector<Index> next(start.begin(), start.end() - 1);
  for (size_t s = 0; s < springs; ++s) {
    const Index at[2] = {i[s], j[s]};
    for (Index side = 0; side < 2; ++side) {
      const Index r = row_of(at[side]);
      if (r >= 0)
        ends[static_cast<size_t>(next[static_cast<size_t>(r)]++)] =
            2 * static_cast<Index>(s) + side;
    }
  }
}

}  // namespace clothlab::fast
