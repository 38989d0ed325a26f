// vbd.cpp: Vertex Block Descent's sweeps in the engine room (FastEngine::vbd_sweeps).
//
// The lecture's loop (integrators/vbd.cpp) sweeps the vertices colour by colour, and within a
// colour no two vertices share a spring: no vertex step reads a position another writes. So here
// a colour's vertices are split over the threads, each thread stepping a contiguous range of them
// with the same kernel (vbd_vertex_step) on the same values, its springs in the same order: the
// same bits as the lecture's loop, on any number of threads.
//
// What the lecture's loop does per vertex and this one does once a step: look up each spring's
// constants through its spring set (two pointer hops and three arrays per spring), into a list
// that grows as it is filled. Here the constants of every spring at every vertex sit in one array
// in the sweep's order, filled once a step (plasticity changes rest lengths between steps, never
// within one), and each thread gathers into a list of its own that never shrinks.
#include <algorithm>
#include <vector>

#include "clothlab/core/stop.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/vbd.hpp"
#include "fast/engine.hpp"

namespace clothlab::fast {

bool FastEngine::vbd_sweeps(World& world, const VbdGraph& graph, const Matrix3X& x_n,
                            const Matrix3X& y, double h, int iterations) {
  Particles& p = world.particles;
  const size_t entries = graph.other.size();
  vbd_springs_.resize(entries);
  for (size_t e = 0; e < entries; ++e) {
    const SpringSet& s = *graph.set[e];
    const size_t m = graph.k[e];
    vbd_springs_[e] = {graph.other[e], s.ks(m), s.kd(m), s.l0(m)};
  }
  // Vertices [begin, end) of the sweep's order, each one Newton step.
  const auto step_range = [&](size_t begin, size_t end) {
    thread_local std::vector<VertexSpring> springs;
    for (size_t c = begin; c < end; ++c) {
      const Index i = graph.order[c];
      if (p.inv_m[i] == 0.0) continue;
      const auto at = static_cast<size_t>(i);
      springs.clear();
      for (size_t e = graph.start[at]; e < graph.start[at + 1]; ++e) {
        const VbdSpring& s = vbd_springs_[e];
        springs.push_back({p.x.col(s.other), x_n.col(s.other), s.ks, s.kd, s.l0});
      }
      p.x.col(i) += vbd_vertex_step(p.x.col(i), x_n.col(i), y.col(i), p.inv_m[i], h, springs);
    }
  };
  for (int it = 0; it < iterations; ++it) {
    stop_point();  // as the lecture's loop: a long run may be asked to stop between sweeps
    for (size_t q = 0; q < static_cast<size_t>(graph.colours()); ++q) {
      const size_t first = graph.colour_start[q];
      const size_t count = graph.colour_start[q + 1] - first;
      if (world.threads <= 1 || count < static_cast<size_t>(std::max<Index>(vbd_split, 1))) {
        step_range(first, first + count);
        continue;
      }
      world.for_items(static_cast<Index>(count), [&](Index begin, Index end) {
        step_range(first + static_cast<size_t>(begin), first + static_cast<size_t>(end));
      });
    }
  }
  return true;
}

}  // namespace clothlab::fast
