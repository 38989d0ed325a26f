#include "clothlab/fast_forces.hpp"

#include "clothlab/threads.hpp"
#include "clothlab/world.hpp"

namespace clothlab {

namespace {

// Columns for n particles in a SoA3 whose rows start `lines` cache lines apart, modulo 4 KiB.
// Rows n apart, for a cloth of 2^k particles, would start at the same place of a 4 KiB page,
// and the processor's first-level cache keeps only 8 lines with the same such place: a spring's
// dozen inputs, all read at once, would evict each other. Each SoA3 gets its own spacing.
Index padded(Index n, Index lines) {
  const Index period = 4096 / sizeof(double), shift = lines * 64 / sizeof(double);
  return n + ((shift - n) % period + period) % period;
}

}  // namespace

bool prepare_fast_forces(const World& world, FastScratch& scratch) {
  const auto& effects = world.force_effects;
  scratch.soa.resize(effects.size());
  bool any = false;
  for (size_t e = 0; e < effects.size(); ++e) {
    scratch.soa[e] = effects[e]->adds_soa(world.particles);
    any = any || scratch.soa[e];
  }
  return any;
}

void fast_forces(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f,
                 FastScratch& scratch, ThreadTeam* team) {
  const auto& effects = world.force_effects;
  const Index n = x.cols();
  scratch.x.resize(3, padded(n, 21));
  scratch.v.resize(3, padded(n, 7));
  scratch.f.resize(3, padded(n, 49));
  f.resize(3, n);
  // Eigen copies between the two storage orders, transposing as it goes.
  for_ranges(team, n, [&](Index begin, Index end) {
    scratch.x.middleCols(begin, end - begin) = x.middleCols(begin, end - begin);
    scratch.v.middleCols(begin, end - begin) = v.middleCols(begin, end - begin);
    scratch.f.middleCols(begin, end - begin).setZero();
  });
  const auto move_f = [&](bool to_soa) {
    for_ranges(team, n, [&](Index begin, Index end) {
      if (to_soa) {
        scratch.f.middleCols(begin, end - begin) = f.middleCols(begin, end - begin);
      } else {
        f.middleCols(begin, end - begin) = scratch.f.middleCols(begin, end - begin);
      }
    });
  };
  // The effects in the world's order; f moves to whichever layout the next effect works on.
  // Consecutive effects with a fast path share one pass of the threads: each thread lets every
  // one of them add its forces on the thread's own particles.
  bool in_soa = true;
  for (size_t e = 0; e < effects.size();) {
    if (!scratch.soa[e]) {
      if (in_soa) move_f(false);
      in_soa = false;
      effects[e]->add_forces(world.particles, x, v, f);
      ++e;
      continue;
    }
    size_t last = e + 1;
    while (last < effects.size() && scratch.soa[last])
      ++last;
    if (!in_soa) move_f(true);
    in_soa = true;
    for_ranges(team, n, [&](Index begin, Index end) {
      for (size_t k = e; k < last; ++k)
        effects[k]->add_forces_soa(world.particles, scratch.x, scratch.v, scratch.f, begin, end);
    });
    e = last;
  }
  if (in_soa) move_f(false);
}

}  // namespace clothlab
