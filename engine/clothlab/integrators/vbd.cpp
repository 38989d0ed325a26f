#include "clothlab/integrators/vbd.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "clothlab/core/backend.hpp"
#include "clothlab/core/stop.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

int vbd_colouring(const std::vector<size_t>& start, const std::vector<Index>& neighbour,
                  std::vector<int>& colour) {
  const size_t n = start.empty() ? 0 : start.size() - 1;
  colour.assign(n, -1);  // -1: not coloured yet
  // seen_by[q] == i: a neighbour of vertex i has colour q (so no array is cleared per vertex).
  std::vector<size_t> seen_by;
  int colours = 0;
  for (size_t i = 0; i < n; ++i) {
    for (size_t e = start[i]; e < start[i + 1]; ++e) {
      const int q = colour[static_cast<size_t>(neighbour[e])];
      if (q >= 0) seen_by[static_cast<size_t>(q)] = i;
    }
    int q = 0;  // the smallest colour no neighbour has
    while (q < colours && seen_by[static_cast<size_t>(q)] == i)
      ++q;
    if (q == colours) {
      ++colours;
      seen_by.push_back(n);  // n: seen by no vertex
    }
    colour[i] = q;
  }
  return colours;
}

void VbdGraph::build(Index particles, const std::vector<const SpringSet*>& families) {
  const auto n = static_cast<size_t>(particles);
  // Count each vertex's springs, then place each spring at both its ends (compressed rows).
  start.assign(n + 1, 0);
  for (const SpringSet* s : families) {
    for (size_t m = 0; m < s->size(); ++m) {
      ++start[static_cast<size_t>(s->i(m)) + 1];
      ++start[static_cast<size_t>(s->j(m)) + 1];
    }
  }
  for (size_t i = 0; i < n; ++i)
    start[i + 1] += start[i];
  other.resize(start[n]);
  set.resize(start[n]);
  k.resize(start[n]);
  std::vector<size_t> next(start.begin(), start.end() - 1);
  const auto place = [&](Index at, Index to, const SpringSet* s, size_t m) {
    const size_t e = next[static_cast<size_t>(at)]++;
    other[e] = to;
    set[e] = s;
    k[e] = m;
  };
  for (const SpringSet* s : families) {
    for (size_t m = 0; m < s->size(); ++m) {
      place(s->i(m), s->j(m), s, m);
      place(s->j(m), s->i(m), s, m);
    }
  }
  // The colours, and the vertices sorted by colour (a counting sort, ascending within each).
  const int count = vbd_colouring(start, other, colour);
  colour_start.assign(static_cast<size_t>(count) + 1, 0);
  for (int q : colour)
    ++colour_start[static_cast<size_t>(q) + 1];
  for (size_t q = 0; q < static_cast<size_t>(count); ++q)
    colour_start[q + 1] += colour_start[q];
  order.resize(n);
  std::vector<size_t> fill(colour_start.begin(), colour_start.end() - 1);
  for (size_t i = 0; i < n; ++i)
    order[fill[static_cast<size_t>(colour[i])]++] = static_cast<Index>(i);
}

void Vbd::adaptive_guess(Particles& p, const Vec3& g, double h) {
  // x = x_n + h v_n + h^2 a g/|g|, a = the last step's acceleration along g, clamped to [0, |g|]
  // (vbd.hpp). Without a last step (the first, or the particles changed) a is taken as 0.
  const Index n = p.size();
  const double g_norm = g.norm();
  const bool have_last = v_previous_.cols() == n && g_norm > 0.0;
  for (Index i = 0; i < n; ++i) {
    if (p.inv_m[i] == 0.0) continue;  // a pin goes where its velocity takes it, as in y
    double a = 0.0;
    if (have_last) {
      a = (p.v.col(i) - v_previous_.col(i)).dot(g) / (h * g_norm);
      a = std::clamp(a, 0.0, g_norm);
    }
    p.x.col(i) = x_n_.col(i) + h * p.v.col(i);
    if (a > 0.0) p.x.col(i) += (h * h * a / g_norm) * g;
  }
}

std::string Vbd::iterations_that_may_stop_short() const {
  return "its " + std::to_string(iterations) + (iterations == 1 ? " sweep" : " sweeps") +
         " a step (iterations = " + std::to_string(iterations) + ")";
}

void Vbd::advance(World& world, double dt) {
  Particles& p = world.particles;
  const Index n = p.size();
  const double h = dt;

  // The springs ("springs", "bending") are the vertex steps' energy; every other force effect is
  // an external force. Looked up each step: tearing removes springs between steps, and the
  // graph is built again when a set's ends or constants change (SpringSet::version).
  std::vector<const SpringSet*> families;
  std::vector<unsigned long> versions;
  Vec3 gravity_g = Vec3::Zero();  // gravity's acceleration, for the adaptive initial guess
  f_ext_.setZero(3, n);
  ++world.force_evaluations;  // one sum of the external forces a step (reports)
  for (const auto& effect : world.force_effects) {
    if (const auto* springs = dynamic_cast<const SpringDampers*>(effect.get())) {
      families.push_back(&springs->springs());
      versions.push_back(springs->springs().version());
    } else {
      if (const auto* gravity = dynamic_cast<const UniformGravity*>(effect.get()))
        gravity_g += gravity->g();
      effect->add_forces(p, p.x, p.v, f_ext_);
    }
  }
  if (families != built_from_ || versions != versions_ ||
      graph_.start.size() != static_cast<size_t>(n) + 1) {
    graph_.build(n, families);
    built_from_ = families;
    versions_ = versions;
    ++graph_builds;
  }

  // y = x_n + h v_n + h^2 M^-1 f_ext, and the initial guess x = y (or the adaptive guess,
  // vbd.hpp). A pinned vertex (inv_m = 0) moves by h v_n, its pin's velocity, and stays there.
  x_n_ = p.x;
  y_.resize(3, n);
  for (Index i = 0; i < n; ++i)
    y_.col(i) = x_n_.col(i) + h * p.v.col(i) + (h * h * p.inv_m[i]) * f_ext_.col(i);
  p.x = y_;
  if (initial_guess == VbdInitialGuess::adaptive) adaptive_guess(p, gravity_g, h);

  // The sweeps: colour by colour, each free vertex one Newton step with its neighbours where
  // they are now (Gauss-Seidel). The rest lengths are read each time (plasticity changes them).
  // The world's backend may take them (the same bits); else this loop does.
  const VbdGraph& g = graph_;
  const bool taken = world.backend && world.backend->vbd_sweeps(world, g, x_n_, y_, h, iterations);
  if (taken) ++backend_steps;
  for (int it = 0; it < (taken ? 0 : iterations); ++it) {
    stop_point();  // many iterations of a big cloth can take a while (core/stop.hpp)
    for (size_t q = 0; q < static_cast<size_t>(g.colours()); ++q) {
      for (size_t c = g.colour_start[q]; c < g.colour_start[q + 1]; ++c) {
        const Index i = g.order[c];
        if (p.inv_m[i] == 0.0) continue;
        springs_.clear();  // the springs at i, their other ends where they are now
        const auto at = static_cast<size_t>(i);
        for (size_t e = g.start[at]; e < g.start[at + 1]; ++e) {
          const SpringSet& s = *g.set[e];
          const size_t m = g.k[e];
          springs_.push_back(
              {p.x.col(g.other[e]), x_n_.col(g.other[e]), s.ks(m), s.kd(m), s.l0(m)});
        }
        p.x.col(i) += vbd_vertex_step(p.x.col(i), x_n_.col(i), y_.col(i), p.inv_m[i], h, springs_);
      }
    }
  }

  // Implicit Euler's velocity, v = (x - x_n) / h; a pinned vertex keeps its pin's velocity.
  v_previous_ = p.v;  // v_n, for the next step's adaptive guess
  for (Index i = 0; i < n; ++i) {
    if (p.inv_m[i] != 0.0) p.v.col(i) = (p.x.col(i) - x_n_.col(i)) / h;
  }
}

}  // namespace clothlab
