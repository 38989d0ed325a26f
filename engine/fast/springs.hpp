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
