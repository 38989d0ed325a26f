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
//
// xpbd_access_passes makes the same passes with the projection replaced by a few multiply-adds
// (access_only): what the layout, the colour order, the gathers and the scatters cost without
// the projection's square roots and divisions, the bound `clothlab bench methods --speed`
// prints beside an XPBD iteration.
#include <algorithm>
#include <vector>

#include "clothlab/core/world.hpp"
#include "clothlab/integrators/xpbd.hpp"
#include "fast/engine.hpp"
#include "fast/vectorise.hpp"

namespace clothlab::fast {

namespace {

// The bound's stand-in for xpbd_project: the same arguments read and the same two ends and
// multiplier returned, joined by multiply-adds alone (no square root, no division, no branch).
// It moves each end by about 1e-15 of the spacing a pass: no method, only the access pattern.
inline double access_only(Vec3& x_i, Vec3& x_j, const Vec3& old_i, const Vec3& old_j, double w_i,
                          double w_j, double ks, double kd, double l0, double h, double lambda) {
  const Vec3 d = x_i - x_j;
  const double c = d.squaredNorm() - l0 * l0 + kd * d.dot((x_i - old_i) - (x_j - old_j));
  const double delta = -1e-12 * h * (ks * c + lambda);
  x_i += (w_i * delta) * d;
  x_j -= (w_j * delta) * d;
  return delta;
}

// Constraints [begin, end) of one colour projected once by `kernel` (xpbd_project, or
// access_only): Xpbd::advance's loop on a range, the positions in the fast layout (component d
// of particle i at x[d nx + i]). No two of these constraints share a particle (the colouring),
// which is what the vectorise hint says.
template <class Kernel>
[[gnu::noinline, gnu::flatten]] void project_range(
    size_t begin, size_t end, const Index* __restrict ci, const Index* __restrict cj,
    const double* __restrict ks, const double* __restrict kd, const double* __restrict l0,
    const double* __restrict inv_m, double* __restrict x, Index nx, const double* __restrict old,
    Index no, double h, double* __restrict lambda, bool keep_lambda, Kernel kernel) {
  // Not in a WebAssembly module (engine/web/): its SIMD has no gathers, and the link-time
  // optimiser there reports a hinted loop it does not vectorise.
#if !defined(__wasm__)
  CLOTHLAB_INDEPENDENT_ITERATIONS
#endif
  for (size_t c = begin; c < end; ++c) {
    const Index i = ci[c], j = cj[c];
    Vec3 x_i(x[i], x[nx + i], x[2 * nx + i]), x_j(x[j], x[nx + j], x[2 * nx + j]);
    const double delta_lambda = kernel(x_i, x_j, Vec3(old[i], old[no + i], old[2 * no + i]),
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

// `iterations` passes of `kernel` over the constraints, colour by colour, each colour split over
// the threads when it has xpbd_split constraints or more; x and x_old in the fast layout (xs,
// olds) for the passes, x copied back after them.
template <class Kernel>
void colour_passes(World& world, const XpbdConstraints& cs, const Matrix3X& x_old, double h,
                   int iterations, bool keep_lambda, std::vector<double>& lambda, SoA3Matrix& xs,
                   SoA3Matrix& olds, Index split, Kernel kernel) {
  Particles& p = world.particles;
  const Index n = p.size();
  xs.resize(3, padded_columns<double>(n, 21));
  olds.resize(3, padded_columns<double>(n, 7));
  const Index nx = xs.cols(), no = olds.cols();
  world.for_particles([&](Index begin, Index end) {
    to_soa(begin, end, p.x.data(), xs.data(), nx);
    to_soa(begin, end, x_old.data(), olds.data(), no);
  });
  const auto project = [&](size_t begin, size_t end) {
    project_range(begin, end, cs.i.data(), cs.j.data(), cs.ks.data(), cs.kd.data(), cs.l0.data(),
                  p.inv_m.data(), xs.data(), nx, olds.data(), no, h, lambda.data(), keep_lambda,
                  kernel);
  };
  for (int it = 0; it < iterations; ++it) {
    for (int q = 0; q < cs.colours(); ++q) {
      const size_t first = cs.colour_start[static_cast<size_t>(q)];
      const size_t count = cs.colour_start[static_cast<size_t>(q) + 1] - first;
      if (world.threads <= 1 || count < static_cast<size_t>(std::max<Index>(split, 1))) {
        project(first, first + count);
        continue;
      }
      world.for_items(static_cast<Index>(count), [&](Index begin, Index end) {
        project(first + static_cast<size_t>(begin), first + static_cast<size_t>(end));
      });
    }
  }
  world.for_particles(
      [&](Index begin, Index end) { from_soa(begin, end, xs.data(), nx, p.x.data()); });
}

}  // namespace

bool FastEngine::xpbd_project(World& world, const XpbdConstraints& constraints,
                              const Matrix3X& x_old, double h, int iterations, bool keep_lambda,
                              std::vector<double>& lambda) {
  colour_passes(world, constraints, x_old, h, iterations, keep_lambda, lambda, xpbd_x_, xpbd_old_,
                xpbd_split, [](auto&&... a) { return clothlab::xpbd_project(a...); });
  return true;
}

void FastEngine::xpbd_access_passes(World& world, const XpbdConstraints& constraints,
                                    const Matrix3X& x_old, double h, int iterations,
                                    std::vector<double>& lambda) {
  colour_passes(world, constraints, x_old, h, iterations, true, lambda, xpbd_x_, xpbd_old_,
                xpbd_split, [](auto&&... a) { return access_only(a...); });
}

}  // namespace clothlab::fast
