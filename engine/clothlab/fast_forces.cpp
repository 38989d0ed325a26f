#include "clothlab/fast_forces.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

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

// Particles [begin, end) of a (the engine's layout: x, y, z of particle i at a[3 i], a[3 i + 1],
// a[3 i + 2]) into s (rows `stride` apart), or back. One pass, particle by particle: each
// particle's three components come from one cache line, where copying row by row would read a
// three times over.
[[gnu::noinline]] void to_soa(Index begin, Index end, const double* __restrict a,
                              double* __restrict s, Index stride) {
  for (Index i = begin; i < end; ++i) {
    s[i] = a[3 * i];
    s[stride + i] = a[3 * i + 1];
    s[2 * stride + i] = a[3 * i + 2];
  }
}

// to_soa, and whether every component it copied is within bound: the guard's test
// (Guard::within, |a| <= bound, false for a NaN) on the values in hand, where a pass of its own
// would read them again.
[[gnu::noinline]] bool to_soa_within(Index begin, Index end, const double* __restrict a,
                                     double* __restrict s, Index stride, double bound) {
  long outside = 0;
  for (Index i = begin; i < end; ++i) {
    const double ax = a[3 * i], ay = a[3 * i + 1], az = a[3 * i + 2];
    s[i] = ax;
    s[stride + i] = ay;
    s[2 * stride + i] = az;
    outside += !(std::abs(ax) <= bound) + !(std::abs(ay) <= bound) + !(std::abs(az) <= bound);
  }
  return outside == 0;
}

[[gnu::noinline]] void from_soa(Index begin, Index end, const double* __restrict s, Index stride,
                                double* __restrict a) {
  for (Index i = begin; i < end; ++i) {
    a[3 * i] = s[i];
    a[3 * i + 1] = s[stride + i];
    a[3 * i + 2] = s[2 * stride + i];
  }
}

}  // namespace

void FastScratch::resize(Index n) {
  x.resize(3, padded(n, 21));
  v.resize(3, padded(n, 7));
  f.resize(3, padded(n, 49));
}

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
                 FastScratch& scratch, ThreadTeam* team, const MoveRange* move,
                 StepChecks* checks) {
  const auto& effects = world.force_effects;
  const Index n = x.cols();
  scratch.resize(n);
  f.resize(3, n);
  std::atomic<bool> start_within = true;
  for_ranges(team, n, [&](Index begin, Index end) {
    if (!checks) {
      to_soa(begin, end, x.data(), scratch.x.data(), scratch.x.cols());
      to_soa(begin, end, v.data(), scratch.v.data(), scratch.v.cols());
    } else {
      const bool x_within = to_soa_within(begin, end, x.data(), scratch.x.data(), scratch.x.cols(),
                                          world.guard.max_position);
      const bool v_within = to_soa_within(begin, end, v.data(), scratch.v.data(), scratch.v.cols(),
                                          world.guard.max_speed);
      if (!x_within || !v_within) start_within = false;
    }
    scratch.f.middleCols(begin, end - begin).setZero();
  });
  // The step's state was bad before it began: the guard names the particle and throws, before
  // anything moves.
  if (!start_within) world.guard.check(world, /*before_step=*/true);
  const auto move_f = [&](bool soa) {
    for_ranges(team, n, [&](Index begin, Index end) {
      if (soa) {
        to_soa(begin, end, f.data(), scratch.f.data(), scratch.f.cols());
      } else {
        from_soa(begin, end, scratch.f.data(), scratch.f.cols(), f.data());
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
    const bool move_here = move && last == effects.size();
    const bool check_end = move_here && checks && checks->end;
    std::atomic<bool> end_within = true;
    for_ranges(team, n, [&](Index begin, Index end) {
      if (!move_here) {
        for (size_t k = e; k < last; ++k)
          effects[k]->add_forces_soa(world.particles, scratch.x, scratch.v, scratch.f, begin, end);
        return;
      }
      // Block by block (World::pass_block): every effect adds its forces on the block, then the
      // block moves, while its x, v and f are still in the cache. These particles' forces are
      // final: no other block or thread adds to them. The others read x and v from the copies,
      // so moving these in x and v changes nothing they see.
      const Particles& p = world.particles;
      const Index block = std::max<Index>(world.pass_block, 1);
      for (Index b0 = begin; b0 < end; b0 += block) {
        const Index b1 = std::min(b0 + block, end);
        for (size_t k = e; k < last; ++k)
          effects[k]->add_forces_soa(p, scratch.x, scratch.v, scratch.f, b0, b1);
        for (Index c0 = b0; c0 < b1; c0 += kPassChunk) {
          const Index c1 = std::min(c0 + kPassChunk, b1);
          from_soa(c0, c1, scratch.f.data(), scratch.f.cols(), f.data());
          (*move)(c0, c1, &scratch);
          if (check_end && !world.guard.within(p.x, p.v, c0, c1)) end_within = false;
        }
      }
    });
    if (check_end) {
      checks->end_checked = true;
      checks->end_within = end_within;
    }
    if (move_here) return;
    e = last;
  }
  if (in_soa) move_f(false);
  if (move) for_ranges(team, n, [&](Index begin, Index end) { (*move)(begin, end, nullptr); });
}

}  // namespace clothlab
