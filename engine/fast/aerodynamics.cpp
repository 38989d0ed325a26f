// aerodynamics.cpp: the fast engine's air on the cloth's triangles (Aerodynamics).
//
// Aerodynamics::add_forces is the lecture's loop. The fast engine evaluates the exercise kernel
// (inlined at link time) on four triangles at once, and every particle still sums the same
// numbers in the same order as there. The loops are templates on the copies' scalar: on doubles
// they call the exercise's kernel, on floats (the float room) the same formula in float
// (aerodynamic_force_of, scalar_kernels.hpp). The list is cut into groups (triangle_groups):
//
// - a run, such as a grid's row: its triangles alternate between phases whose corners move one
//   particle per triangle, so the kernel reads them straight from the fast path's rows. The
//   shares go out in one pass per (phase, corner), in the order in which a particle meets them
//   in the list (the pass with the earlier list position for every particle first);
// - other triangles: their corners are gathered 128 at a time into rows of their own, and their
//   shares go to the corners one triangle after the other, as add_forces adds them.
//
// A thread takes the triangles with a corner in its range and adds to those corners only.
#include "fast/aerodynamics.hpp"

#include <algorithm>
#include <type_traits>
#include <utility>

#include "clothlab/forces/aerodynamics.hpp"
#include "fast/forces.hpp"
#include "fast/scalar_kernels.hpp"
#include "fast/vectorise.hpp"

namespace clothlab::fast {

namespace {

constexpr Index kTriangleChunk = 128;  // triangles per chunk: 21 KiB of gathered inputs

// share = aerodynamic_force(...) / 3 of triangles i = 0 .. count - 1, whose corner c has its
// components at xc[i], xc[nx + i], xc[2 nx + i] and its velocity's at vc[i], vc[nv + i], ...;
// the shares go to rows 0-2 of `share`, kTriangleChunk apart. A run's corners are read where
// they are; gathered ones from rows kTriangleChunk long. Not inlined, so that its pointers can be
// declared not to overlap what it writes: then the compiler vectorises the loop.
template <class S>
[[gnu::noinline, gnu::flatten]] void aerodynamic_shares(
    Index count, Index nx, Index nv, const S* __restrict x1, const S* __restrict x2,
    const S* __restrict x3, const S* __restrict v1, const S* __restrict v2, const S* __restrict v3,
    S* __restrict share, const Vec3Of<S> v_air, S rho, S cd) {
  constexpr Index n = kTriangleChunk;
  const auto at = [](const S* a, Index stride, Index i) {
    return Vec3Of<S>(a[i], a[stride + i], a[2 * stride + i]);
  };
  for (Index i = 0; i < count; ++i) {
    // The kernel called here, not through a wrapper: Clang's `flatten` (the page's build)
    // inlines one level of calls, and the loop vectorises only with the kernel inlined.
    Vec3Of<S> f_aero;
    if constexpr (std::is_same_v<S, double>) {
      f_aero = aerodynamic_force(at(x1, nx, i), at(x2, nx, i), at(x3, nx, i), at(v1, nv, i),
                                 at(v2, nv, i), at(v3, nv, i), v_air, rho, cd);
    } else {
      f_aero = aerodynamic_force_of<S>(at(x1, nx, i), at(x2, nx, i), at(x3, nx, i), at(v1, nv, i),
                                       at(v2, nv, i), at(v3, nv, i), v_air, rho, cd);
    }
    const Vec3Of<S> s = f_aero / S(3);  // each corner carries a third of the triangle
    share[i] = s.x();
    share[n + i] = s.y();
    share[2 * n + i] = s.z();
  }
}

// aerodynamic_shares in whole vectors: the triangles up to the last multiple of the vector's
// width, then the last vector's worth once more, overlapping the first part and writing there
// again the shares it wrote (each lane's share is the kernel on its own triangle, the same
// operations in any lane: the same bits). The compiler's remainder, one triangle at a time at a
// lane's cost several times over, is left to groups shorter than a vector, and to builds whose
// vectors hold two values (kWholeVectorEnds, vectorise.hpp).
template <class S>
void shares_in_vectors(Index count, Index nx, Index nv, const S* x1, const S* x2, const S* x3,
                       const S* v1, const S* v2, const S* v3, S* share, const Vec3Of<S>& v_air,
                       S rho, S cd) {
  constexpr Index kLanes = kVectorLanes<S>;
  const Index whole = count - count % kLanes;
  if (!kWholeVectorEnds<S> || whole == count || whole == 0) {
    aerodynamic_shares(count, nx, nv, x1, x2, x3, v1, v2, v3, share, v_air, rho, cd);
    return;
  }
  aerodynamic_shares(whole, nx, nv, x1, x2, x3, v1, v2, v3, share, v_air, rho, cd);
  const Index t = count - kLanes;
  aerodynamic_shares(kLanes, nx, nv, x1 + t, x2 + t, x3 + t, v1 + t, v2 + t, v3 + t, share + t,
                     v_air, rho, cd);
}

}  // namespace

// Aerodynamics::add_forces on the copies, group by group; the groups are cut again when the
// triangle list changes (Aerodynamics::version). On copies in S: the wind, rho and cd are read
// at each evaluation (a gust changes the wind) and rounded to S.
template <class S>
class FastAerodynamics final : public FastForceOf<S> {
  using SoA = SoA3Of<S>;

 public:
  explicit FastAerodynamics(const Aerodynamics& aero) : aero_(aero) {}
  bool prepare(const Particles& /*p*/) override {
    if (!built_ || version_ != aero_.version()) {
      groups_ = triangle_groups(aero_.triangles());
      version_ = aero_.version();
      built_ = true;
    }
    return true;
  }
  void add(const Particles& /*p*/, const SoA& x, const SoA& v, SoA& f, Index begin,
           Index end) const override {
    for (const TriangleGroup& g : groups_)
      add_group(g, x, v, f, begin, end);
  }

 private:
  void add_group(const TriangleGroup& g, const SoA& x, const SoA& v, SoA& f, Index begin,
                 Index end) const;
  void add_triangles(size_t k_begin, size_t k_end, const SoA& x, const SoA& v, SoA& f, Index begin,
                     Index end) const;
  Vec3Of<S> wind() const { return aero_.wind().cast<S>(); }
  S rho() const { return static_cast<S>(aero_.rho()); }
  S cd() const { return static_cast<S>(aero_.cd()); }

  const Aerodynamics& aero_;
  std::vector<TriangleGroup> groups_;
  bool built_ = false;
  unsigned long version_ = 0;
};

template <class S>
void FastAerodynamics<S>::add_triangles(size_t k_begin, size_t k_end, const SoA& x, const SoA& v,
                                        SoA& f, Index begin, Index end) const {
  constexpr Index n = kTriangleChunk;
  const auto in_range = [&](Index i) { return begin <= i && i < end; };
  S in[18 * n];
  S share[3 * n];
  size_t chunk[n];  // which triangle each column of `in` holds
  for (size_t k = k_begin; k < k_end;) {
    Index count = 0;
    for (; k < k_end && count < n; ++k) {
      const Triangle& t = aero_.triangles()[k];
      if (!in_range(t[0]) && !in_range(t[1]) && !in_range(t[2])) continue;
      chunk[count] = k;
      for (int c = 0; c < 3; ++c) {
        for (int d = 0; d < 3; ++d) {
          in[(3 * c + d) * n + count] = x(d, t[c]);
          in[(9 + 3 * c + d) * n + count] = v(d, t[c]);
        }
      }
      ++count;
    }
    // Rows of `in`: x, y, z of corners 1, 2, 3, then their velocities.
    shares_in_vectors(count, n, n, in, in + 3 * n, in + 6 * n, in + 9 * n, in + 12 * n, in + 15 * n,
                      share, wind(), rho(), cd());
    for (Index q = 0; q < count; ++q) {
      for (Index corner : aero_.triangles()[chunk[q]]) {
        if (!in_range(corner)) continue;
        for (int d = 0; d < 3; ++d)
          f(d, corner) += share[d * n + q];
      }
    }
  }
}

std::vector<TriangleGroup> triangle_groups(const std::vector<Triangle>& triangles) {
  constexpr Index kMinRun = 8;  // shorter runs cost more in bookkeeping than they save
  std::vector<TriangleGroup> groups;
  const size_t count = triangles.size();
  const auto shifted = [](const Triangle& t, Index i) {
    return Triangle{t[0] + i, t[1] + i, t[2] + i};
  };
  for (size_t k = 0; k < count;) {
    TriangleGroup run;
    for (int period : {2, 1}) {
      if (k + static_cast<size_t>(period) > count) continue;
      Index length = 1;
      const auto continues = [&](Index i) {
        const size_t at = k + static_cast<size_t>(period * i);
        if (at + static_cast<size_t>(period) > count) return false;
        for (int p = 0; p < period; ++p) {
          if (triangles[at + static_cast<size_t>(p)] != shifted(triangles[k + p], i)) return false;
        }
        return true;
      };
      while (continues(length))
        ++length;
      if (length >= kMinRun) {
        run = {k, static_cast<size_t>(period * length), true, period, length, {}, {}};
        break;
      }
    }
    if (!run.run) {
      // One more triangle taken one by one: with the previous ones if they were too.
      if (groups.empty() || groups.back().run) groups.push_back({k, 0, false, 1, 0, {}, {}});
      ++groups.back().size;
      ++k;
      continue;
    }
    // Particle q is corner c of phase p's triangle i = q - base[p][c], at list position
    // k0 + period (q - base[p][c]) + p: its shares arrive in the order of p - period base[p][c],
    // then of c (a triangle adds to its corners in order).
    std::vector<std::array<int, 2>> order;
    for (int p = 0; p < run.period; ++p) {
      run.base[static_cast<size_t>(p)] = triangles[k + static_cast<size_t>(p)];
      for (int c = 0; c < 3; ++c)
        order.push_back({p, c});
    }
    const auto key = [&](const std::array<int, 2>& pc) {
      return std::pair(
          pc[0] - run.period * run.base[static_cast<size_t>(pc[0])][static_cast<size_t>(pc[1])],
          pc[1]);
    };
    std::sort(order.begin(), order.end(),
              [&](const auto& a, const auto& b) { return key(a) < key(b); });
    std::copy(order.begin(), order.end(), run.order.begin());
    groups.push_back(run);
    k += run.size;
  }
  return groups;
}

template <class S>
void FastAerodynamics<S>::add_group(const TriangleGroup& g, const SoA& x, const SoA& v, SoA& f,
                                    Index begin, Index end) const {
  if (!g.run) {
    add_triangles(g.k0, g.k0 + g.size, x, v, f, begin, end);
    return;
  }
  constexpr Index n = kTriangleChunk;
  const size_t passes = static_cast<size_t>(3 * g.period);
  // The triangles i with a corner in [begin, end).
  Index lowest = g.base[0][0], highest = lowest;
  for (int p = 0; p < g.period; ++p) {
    for (Index corner : g.base[static_cast<size_t>(p)]) {
      lowest = std::min(lowest, corner);
      highest = std::max(highest, corner);
    }
  }
  const Index i_begin = std::clamp<Index>(begin - highest, 0, g.length);
  const Index i_end = std::clamp<Index>(end - lowest, 0, g.length);
  S share[2][3 * n];
  for (Index i0 = i_begin; i0 < i_end; i0 += n) {
    const Index i1 = std::min(i0 + n, i_end);
    for (int p = 0; p < g.period; ++p) {
      const Triangle& b = g.base[static_cast<size_t>(p)];
      shares_in_vectors(i1 - i0, x.cols(), v.cols(), x.data() + b[0] + i0, x.data() + b[1] + i0,
                        x.data() + b[2] + i0, v.data() + b[0] + i0, v.data() + b[1] + i0,
                        v.data() + b[2] + i0, share[static_cast<size_t>(p)], wind(), rho(), cd());
    }
    // Every particle takes its shares in the list's order: pass by pass (see triangle_groups).
    for (size_t k = 0; k < passes; ++k) {
      const auto [p, c] = g.order[k];
      const Index corner = g.base[static_cast<size_t>(p)][static_cast<size_t>(c)];
      const Index t0 = std::max(i0, begin - corner), t1 = std::min(i1, end - corner);
      if (t0 >= t1) continue;
      for (Index d = 0; d < 3; ++d) {
        add_to_row<S, true>(t1 - t0, share[static_cast<size_t>(p)] + d * n + (t0 - i0),
                            f.data() + d * f.cols() + corner + t0);
      }
    }
  }
}

template <class S>
std::unique_ptr<FastForceOf<S>> fast_aerodynamics(const Aerodynamics& aerodynamics) {
  return std::make_unique<FastAerodynamics<S>>(aerodynamics);
}
template std::unique_ptr<FastForceOf<double>> fast_aerodynamics(const Aerodynamics&);
template std::unique_ptr<FastForceOf<float>> fast_aerodynamics(const Aerodynamics&);

}  // namespace clothlab::fast
