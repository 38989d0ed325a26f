// springs.hpp: how the fast engine sees a set of springs (springs.cpp).
#pragma once

#include <vector>

#include "clothlab/forces/spring_damper.hpp"

namespace clothlab::fast {

// A stretch of springs that join consecutive particles: springs k0, k0 + 1, ..., k0 + length - 1
// of a set join particles i0 + t and j0 + t, t = 0, 1, ..., length - 1. A grid's families come in
// such runs (the row springs of row r are one, with j0 = i0 + 1), so a loop over a run reads
// positions and writes forces in memory order, with no index arrays to chase.
struct SpringRun {
  size_t k0;             // first spring of the run in the set
  Index i0, j0;          // particles of its first spring
  Index length;          // springs in the run
  bool uniform = false;  // all its springs have the ks and the kd of its first, bit for bit
  bool operator==(const SpringRun&) const = default;
};

// The springs of `s`, in their order, cut into the longest runs they form. A set without such
// structure comes out as runs of length 1; the runs always cover every spring exactly once. A
// run is `uniform` when its springs share one ks and one kd (a family added by
// add_spring_family): the fast path then reads them once for the run.
std::vector<SpringRun> spring_runs(const SpringSet& s);

// A grid's family cut into runs gives one run per row (its row springs, its diagonals), or one
// run for all its rows (its column springs). A stencil takes such rows as one: `rows` rows of
// `length` springs, `stride` particles apart (stride >= length), row r's spring c being spring
// k0 + r length + c of the set, joining particles i0 + r stride + c and j0 + r stride + c. Every
// spring has the stencil's ks and kd, bit for bit, and its rest length as built (l0 == l_built,
// bit for bit): a spring that has yielded, or whose l0 was set by hand, is in no stencil.
//
// The rest lengths are not one number: a grid's particles are placed at origin + c spacing, and
// (c + 1) spacing - c spacing rounds to a handful of values along a row (9 for the 127 row springs
// of bench speed's 128 x 128 cloth). But rows repeat: the row springs of every row have the same
// rest lengths, a diagonal's depend on its row through a few values only. So a stencil keeps
// its distinct rows of rest lengths (at most kStencilRestRows), and each row points to one: a
// few KiB that stay in the first-level cache, where the set's l0 streams 8 bytes a spring.
inline constexpr size_t kStencilRestRows = 8;

struct SpringStencil {
  size_t k0;                   // first spring of the stencil in the set
  Index i0, j0;                // particles of its first spring
  Index length;                // springs in a row
  Index stride;                // particles from one row's first spring to the next's
  Index rows;                  // rows
  double ks, kd;               // every spring's [N/m], [N s/m]
  std::vector<double> l0;      // its distinct rows of rest lengths, `length` each [m]
  std::vector<size_t> row_l0;  // row r's rest lengths start at l0[row_l0[r]]
  size_t runs_before;          // runs of the layout that come before it in the set
  size_t springs() const { return static_cast<size_t>(rows * length); }
};

// How the fast path takes a set: stencils where the runs form rows of a grid, and runs for the
// rest, each in the set's order (stencil s comes after runs[0 .. runs_before)).
struct SpringLayout {
  std::vector<SpringRun> runs;
  std::vector<SpringStencil> stencils;
  size_t stencil_springs() const;  // springs in stencils
};

// The layout of `s`, from its runs (spring_runs(s)): consecutive runs that form rows (the same
// length, the same j0 - i0, first ends the same stride apart, uniform, one ks and kd) become a
// stencil of two or more rows; so do the rows of one uniform run whose length is a multiple of
// such a stride (a grid's column springs, rows of its width). The springs of a row that cannot
// join (a row cut short by a tear, a row with a yielded spring or other constants) stay in runs.
SpringLayout spring_layout(const SpringSet& s, const std::vector<SpringRun>& runs);

// The fast path's inner loop: the forces f1 of springs t = 0 .. count - 1 of a run, through
// spring_damper_force. Spring t joins the particles whose components sit at x1[t], x1[nx + t],
// x1[2 nx + t] and x2[t], ... (nx: the stride of x's rows), with velocities at v1[t],
// v1[nv + t], ...; its constants are ks[t], kd[t], l0[t], and f1 goes to f1x[t], f1y[t],
// f1z[t]. No two arrays may overlap. Compiled with the kernel inlined (link-time optimisation),
// it evaluates four or eight springs at once; `clothlab bench speed` times it alone. With
// `uniform`, every spring has the constants ks[0] and kd[0] (SpringRun::uniform).
void spring_forces_of_run(Index count, Index nx, Index nv, const double* x1, const double* x2,
                          const double* v1, const double* v2, const double* ks, const double* kd,
                          const double* l0, double* f1x, double* f1y, double* f1z,
                          bool uniform = false);

// A run whose ends are kDirectGap or more particles apart adds each force straight to both
// ends; closer ones go through a small buffer (springs.cpp says why).
inline constexpr Index kDirectGap = 16;

}  // namespace clothlab::fast
