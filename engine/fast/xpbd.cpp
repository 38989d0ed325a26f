// xpbd.cpp: XPBD's projections in the engine room (FastEngine::xpbd_project).
//
// The lecture's loop (integrators/xpbd.cpp) projects the constraints one after the other, in
// the order of XpbdConstraints: colour by colour, where no two constraints of a colour share a
// particle. So within a colour no projection reads what another writes, and here a colour's
// constraints are split over the threads, each thread projecting a contiguous range of them
// with the same function (xpbd_project) on the same values: the same bits as the lecture's loop,
// on any number of threads. The positions are read from a structure of arrays (all x, then all
// y, then all z), so that, with the kernel inlined (link-time optimisation), the compiler may
// project several constraints of a colour at once with vector instructions. SPEED.md measures it.
#include <algorithm>
#include <vector>

#include "clothlab/core/world.hpp"
#include "clothlab/integrators/xpbd.hpp"
#include "fast/engine.hpp"
#include "fast/vectorise.hpp"

namespace clothlab::fast {

namespace {

// Constraints [begin, end) of one colour projected once: Xpbd::advance's loop on a range, the
// positions in the fast layout (component d of particle i at x[d nx + i]). No two of these
// constraints share a particle (the colouring), which is what the vectorise hint says.
[[gnu::noinline, gnu::flatten]] void project_range(
    size_t begin, size_t end, const Index* __restrict ci, const Index* __restrict cj,
    const double* __restrict ks, const double* __restrict kd, const double* __restrict l0,
    const double* __restrict inv_m, double* __restrict x, Index nx, const double* __restrict old,
    Index no, double h, double* __restrict lambda, bool keep_lambda) {
  // Not in a WebAssembly module (engine/web/): its SIMD has no gathers, and the link-time
  // optimiser there reports a hinted loop it does not vectorise.
#if !defined(__wasm__)
  CLOTHLAB_INDEPENDENT_ITERATIONS
#endif
  for (size_t c = begin; c < end; ++c) {
    const Index i = ci[c], j = cj[c];
    Vec3 x_i(x[i], x[nx + i], x[2 * nx + i]), x_j(x[j], x[nx + j], x[2 * nx + j]);
    const double delta_lambda = xpbd_project(x_i, x_j, Vec3(old[i], old[no + i], old[2 * no + i]),
                                             Vec3(old[j], old[no + j], old[2 * no + j]), inv_m[i],
                                             inv_m[j], ks[c], kd[c], l0[c], h, lambda[c]);
    x[i] = x_i.x();
    x[nx + i] = x_i.y();
    x[2 * nx + i] = x_i.z();
    x[j] = x_j.x();
    x[nx + j] = x_j.y();
    x[2 * nx + j] = x_j.z();
    if (keep_lambda) lambda[c] += delta_lambda;
  }
#if !defined(__wasm__)
  CLOTHLAB_INDEPENDENT_ITERATIONS_END
#endif
}

}  // namespace

bool FastEngine::xpbd_project(World& world, const XpbdConstraints& constraints,
                              const Matrix3X& x_old, double h, int iterations, bool keep_lambda,
                              std::vector<double>& lambda) {
  Particles& p = world.particles;
  const Index n = p.size();
  xpbd_x_.resize(3, Copies::padded(n, 21));
  xpbd_old_.resize(3, Copies::padded(n, 7));
  const Index nx = xpbd_x_.cols(), no = xpbd_old_.cols();
  world.for_particles([&](Index begin, Index end) {
    to_soa(begin, end, p.x.data(), xpbd_x_.data(), nx);
    to_soa(begin, end, x_old.data(), xpbd_old_.data(), no);
  });
  const XpbdConstraints& cs = constraints;
  const auto project = [&](size_t begin, size_t end) {
    project_range(begin, end, cs.i.data(), cs.j.data(), cs.ks.data(), cs.kd.data(), cs.l0.data(),
                  p.inv_m.data(), xpbd_x_.data(), nx, xpbd_old_.data(), no, h, lambda.data(),
                  keep_lambda);
  };
  for (int it = 0; it < iterations; ++it) {
    for (int q = 0; q < cs.colours(); ++q) {
      const size_t first = cs.colour_start[static_cast<size_t>(q)];
      const size_t count = cs.colour_start[static_cast<size_t>(q) + 1] - first;
      if (world.threads <= 1 || count < static_cast<size_t>(std::max<Index>(xpbd_split, 1))) {
        project(first, first + count);
        continue;
      }
      world.for_items(static_cast<Index>(count), [&](Index begin, Index end) {
        project(first + static_cast<size_t>(begin), first + static_cast<size_t>(end));
      });
    }
  }
  world.for_particles(
      [&](Index begin, Index end) { from_soa(begin, end, xpbd_x_.data(), nx, p.x.data()); });
  return true;
}

}  // namespace clothlab::fast
