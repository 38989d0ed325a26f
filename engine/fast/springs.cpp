// springs.cpp: the fast engine's spring-dampers (SpringDampers), run by run and stencil by stencil.
//
// SpringDampers::add_forces is the lecture's loop: for each spring, f1 from the exercise kernel,
// added to one end and subtracted from the other. It reads i[k] and j[k] and jumps to wherever they
// point, so the compiler must take one spring at a time. The fast path computes the same f1 with
// the same kernel, but run by run (see SpringRun): along a run both ends move one particle at a
// time, and in the structure-of-arrays layout every input of spring t + 1 sits just after that
// of spring t. The compiler then evaluates the kernel (inlined at link time) on four springs at
// once (eight with AVX-512). A uniform run (SpringRun::uniform, a family added with one ks and
// one kd) passes its first spring's ks and kd to every spring, so each spring reads one constant
// from memory instead of three (SPEED.md measures what that saves on a large cloth). A run
// is taken in chunks of kChunk springs:
//
//   1. f1 of the chunk's springs into a small buffer (it stays in the processor's nearest cache);
//   2. the chunk's upper ends (the higher particle numbers) take their shares, then its lower
//      ends: f += f1 on the i side, f -= f1 on the j side, as in add_forces.
//
// Bit for bit the same sums: a particle collects its springs in the order add_forces adds them.
// Across runs that is run order. Within a run from particles L0 + t to U0 + t (L0 < U0), a
// particle p is the upper end of spring p - U0 and the lower end of spring p - L0, which comes
// later: in a later chunk, or in the same chunk, where upper ends go first.
//
// Runs whose ends lie kDirectGap or more particles apart (a grid's columns and diagonals) need no
// buffer: each spring's f1 goes straight to both ends (run_kernel_direct below says why the
// order of the sums stays the same).
//
// A grid's rows come as stencils (SpringStencil, springs.hpp): the rows of a family taken one
// after the other, in the set's order, as the runs they replace would be, each through the same
// loops as a run (RunView), so the sums are the same, bit for bit; a row wholly in a thread's
// range goes to those loops directly (add_rows_direct, add_rows_buffered), without the
// bookkeeping of a row that the range may cut. What a stencil saves is the
// rest lengths' stream: its rows read theirs from a few distinct rows of them, which stay in the
// first-level cache, and ks and kd once. SPEED.md measures what that is worth.
//
// With several threads, each owns a contiguous range of particles and adds only to those: it
// takes every spring with an end in its range. A spring between two ranges is computed by both
// threads (the same bits twice); nothing is shared, so there are no locks and no atomics.

#include "fast/springs.hpp"

#include <algorithm>
#include <array>
#include <type_traits>

#include "clothlab/core/world.hpp"
#include "fast/forces.hpp"
#include "fast/scalar_kernels.hpp"
#include "fast/vectorise.hpp"

namespace clothlab::fast {

std::vector<SpringRun> spring_runs(const SpringSet& s) {
  std::vector<SpringRun> runs;
  for (size_t k = 0; k < s.size(); ++k) {
    // Spring k continues the last run if it joins the particles just after its last spring's.
    if (!runs.empty()) {
      SpringRun& last = runs.back();
      if (s.i(k) == last.i0 + last.length && s.j(k) == last.j0 + last.length) {
        last.uniform =
            last.uniform && same_bits(s.ks(k), s.ks(last.k0)) && same_bits(s.kd(k), s.kd(last.k0));
        ++last.length;
        continue;
      }
    }
    runs.push_back({k, s.i(k), s.j(k), 1, true});
  }
  return runs;
}

size_t SpringLayout::stencil_springs() const {
  size_t n = 0;
  for (const SpringStencil& stencil : stencils)
    n += stencil.springs();
  return n;
}

SpringLayout spring_layout(const SpringSet& s, const std::vector<SpringRun>& runs) {
  // Whether row b may follow row a in a stencil whose rows are `stride` particles apart (0: any
  // stride, at least a row's length, so that the rows' springs come in the order of their ends).
  const auto follows = [&](const SpringRun& a, const SpringRun& b, Index stride) {
    const Index step = b.i0 - a.i0;
    return a.uniform && b.uniform && b.length == a.length && b.j0 - b.i0 == a.j0 - a.i0 &&
           step >= a.length && (stride == 0 || step == stride) &&
           same_bits(s.ks(b.k0), s.ks(a.k0)) && same_bits(s.kd(b.k0), s.kd(a.k0));
  };
  // The grid's width: the stride of the first two runs that form rows. A uniform run of a
  // multiple of it (two rows or more) is taken as rows of that many springs.
  Index width = 0;
  for (size_t a = 0; a + 1 < runs.size() && width == 0; ++a) {
    if (follows(runs[a], runs[a + 1], 0)) width = runs[a + 1].i0 - runs[a].i0;
  }
  std::vector<SpringRun> rows;
  rows.reserve(runs.size());
  for (const SpringRun& run : runs) {
    if (width == 0 || !run.uniform || run.length < 2 * width || run.length % width != 0) {
      rows.push_back(run);
      continue;
    }
    for (Index r = 0; r < run.length / width; ++r) {
      const Index t = r * width;
      rows.push_back({run.k0 + static_cast<size_t>(t), run.i0 + t, run.j0 + t, width, true});
    }
  }
  // Every spring of the row at its built rest length, bit for bit.
  const auto as_built = [&](const SpringRun& row) {
    for (size_t k = row.k0; k < row.k0 + static_cast<size_t>(row.length); ++k) {
      if (!same_bits(s.l0(k), s.l_built(k))) return false;
    }
    return true;
  };
  // Where the row's rest lengths start among the stencil's distinct rows of them: a new row of
  // them if there is room, else none.
  constexpr size_t kNone = static_cast<size_t>(-1);
  const auto rest_row = [&](SpringStencil& stencil, const SpringRun& row) {
    const auto l0 = s.l0().begin() + static_cast<std::ptrdiff_t>(row.k0);
    const auto same = [](double a, double b) { return same_bits(a, b); };
    const size_t n = static_cast<size_t>(row.length);
    for (size_t p = 0; p < stencil.l0.size(); p += n) {
      if (std::equal(l0, l0 + row.length, stencil.l0.begin() + static_cast<std::ptrdiff_t>(p),
                     same))
        return p;
    }
    if (stencil.l0.size() >= kStencilRestRows * n) return kNone;
    stencil.l0.insert(stencil.l0.end(), l0, l0 + row.length);
    return stencil.l0.size() - n;
  };
  SpringLayout layout;
  // A row in no stencil goes to the runs, continuing the last one if it can (the rows of a long
  // run on either side of a row that left the stencil), though never across a stencil.
  const auto keep = [&](const SpringRun& row) {
    const bool after_stencil =
        !layout.stencils.empty() && layout.stencils.back().runs_before == layout.runs.size();
    if (!layout.runs.empty() && !after_stencil) {
      SpringRun& last = layout.runs.back();
      const Index n = last.length;
      if (last.k0 + static_cast<size_t>(n) == row.k0 && last.i0 + n == row.i0 &&
          last.j0 + n == row.j0) {
        last.uniform = last.uniform && row.uniform && same_bits(s.ks(row.k0), s.ks(last.k0)) &&
                       same_bits(s.kd(row.k0), s.kd(last.k0));
        last.length += row.length;
        return;
      }
    }
    layout.runs.push_back(row);
  };
  for (size_t a = 0; a < rows.size();) {
    const SpringRun& first = rows[a];
    SpringStencil stencil{first.k0, first.i0, first.j0,          first.length,
                          0,        1,        s.ks(first.k0),    s.kd(first.k0),
                          {},       {},       layout.runs.size()};
    size_t b = a + 1;
    if (first.uniform && as_built(first)) {
      stencil.row_l0.push_back(rest_row(stencil, first));  // the first always has room
      for (; b < rows.size() && follows(rows[b - 1], rows[b], stencil.stride) && as_built(rows[b]);
           ++b) {
        const size_t p = rest_row(stencil, rows[b]);
        if (p == kNone) break;
        stencil.stride = rows[b].i0 - rows[b - 1].i0;
        stencil.row_l0.push_back(p);
      }
    }
    if (b - a < 2) {
      keep(first);
      ++a;
      continue;
    }
    stencil.rows = static_cast<Index>(b - a);
    layout.stencils.push_back(std::move(stencil));
    a = b;
  }
  return layout;
}

namespace {

// A function of its own, not inlined, so that every pointer can be declared not to overlap the
// others: then the compiler vectorises the loop, kernel inlined. With Uniform, ks[0] and kd[0]
// serve every spring: read once, outside the loop, instead of two more numbers per spring.
// S is the scalar of the copies and of the constants: double on the fast path (the exercise's
// kernel on the set's own arrays), float in the float room (spring_kernel, scalar_kernels.hpp, on
// the constants rounded once: FastSprings::Rounded).
template <class S, bool Uniform>
[[gnu::noinline]] void forces_of_run(Index count, Index nx, Index nv, const S* __restrict x1,
                                     const S* __restrict x2, const S* __restrict v1,
                                     const S* __restrict v2, const S* __restrict ks,
                                     const S* __restrict kd, const S* __restrict l0,
                                     S* __restrict f1x, S* __restrict f1y, S* __restrict f1z) {
  using V = Vec3Of<S>;
  for (Index t = 0; t < count; ++t) {
    const V f1 =
        spring_kernel(V(x1[t], x1[nx + t], x1[2 * nx + t]), V(x2[t], x2[nx + t], x2[2 * nx + t]),
                      V(v1[t], v1[nv + t], v1[2 * nv + t]), V(v2[t], v2[nv + t], v2[2 * nv + t]),
                      ks[Uniform ? 0 : t], kd[Uniform ? 0 : t], l0[t]);
    f1x[t] = f1.x();
    f1y[t] = f1.y();
    f1z[t] = f1.z();
  }
}

// forces_of_run on springs 0 .. count - 1 in whole vectors: the springs up to the last multiple
// of kVectorLanes<S> (vectorise.hpp), then the last kVectorLanes<S> springs once more, which
// overlap the first part by less than a vector and write there again what it wrote: each lane's
// f1 is the kernel on that spring's own inputs, the same operations whichever lane takes it, so
// the same bits. The compiler's own remainder (narrower vectors, then one spring at a time, each
// at about twice the cost of a lane: SPEED.md) is never taken, except by a run shorter than one
// vector, or where vectors hold two values (kWholeVectorEnds, vectorise.hpp).
template <class S, bool Uniform>
void forces_in_vectors(Index count, Index nx, Index nv, const S* x1, const S* x2, const S* v1,
                       const S* v2, const S* ks, const S* kd, const S* l0, S* f1x, S* f1y, S* f1z) {
  constexpr Index kLanes = kVectorLanes<S>;
  const Index whole = count - count % kLanes;
  if (!kWholeVectorEnds<S> || whole == count || whole == 0) {
    forces_of_run<S, Uniform>(count, nx, nv, x1, x2, v1, v2, ks, kd, l0, f1x, f1y, f1z);
    return;
  }
  forces_of_run<S, Uniform>(whole, nx, nv, x1, x2, v1, v2, ks, kd, l0, f1x, f1y, f1z);
  const Index t = count - kLanes, k = Uniform ? 0 : t;
  forces_of_run<S, Uniform>(kLanes, nx, nv, x1 + t, x2 + t, v1 + t, v2 + t, ks + k, kd + k, l0 + t,
                            f1x + t, f1y + t, f1z + t);
}

// The energies of springs t = 0 .. count - 1 of a run, the exercise's spring_energy of each (its
// ends x1 + 3 t and x2 + 3 t in the engine's layout, x, y, z side by side), into e[t]. A loop
// of its own, with pointers declared not to overlap and the kernel inlined (`flatten`), so that
// the compiler takes several springs an instruction, square roots included; each lane does the
// operations a spring alone would, so each energy has the same bits.
[[gnu::noinline, gnu::flatten]] void energies_of_run(Index count, const double* __restrict x1,
                                                     const double* __restrict x2,
                                                     const double* __restrict ks,
                                                     const double* __restrict l0,
                                                     double* __restrict e) {
  for (Index t = 0; t < count; ++t) {
    e[t] = spring_energy(Vec3(x1[3 * t], x1[3 * t + 1], x1[3 * t + 2]),
                         Vec3(x2[3 * t], x2[3 * t + 1], x2[3 * t + 2]), ks[t], l0[t]);
  }
}

// The sums of `Blocks` consecutive blocks of `block` values from e: sums[q] = block q's values
// added in order from +0.0, the blocks side by side (sums that do not wait on each other).
template <int Blocks>
void sums_of_blocks(const double* e, Index block, double* sums) {
  double sum[Blocks] = {};
  for (Index k = 0; k < block; ++k) {
    for (int q = 0; q < Blocks; ++q)
      sum[q] += e[q * block + k];
  }
  std::copy_n(sum, Blocks, sums);
}

}  // namespace

void spring_forces_of_run(Index count, Index nx, Index nv, const double* x1, const double* x2,
                          const double* v1, const double* v2, const double* ks, const double* kd,
                          const double* l0, double* f1x, double* f1y, double* f1z, bool uniform) {
  (uniform ? forces_of_run<double, true> : forces_of_run<double, false>)(count, nx, nv, x1, x2, v1,
                                                                         v2, ks, kd, l0, f1x, f1y,
                                                                         f1z);
}

namespace {

constexpr Index kChunk = 256;  // springs per chunk: f1 of a chunk takes 6 KiB

// Runs whose two ends are at least kDirectGap particles apart (a grid's column, diagonal and
// column-bending springs) skip the buffer: each spring's f1 goes straight to both its ends.
// Spring t writes the forces on particles lower + t and upper + t = lower + t + gap; a particle
// that is the upper end of spring t is the lower end of spring t + gap. The compiler is told
// that the loop's passes are independent: true as long as it takes fewer than gap springs at
// once, and it takes 4 (AVX2) or 8 (AVX-512). Each particle then gets its two shares in separate
// passes, upper first, as on the readable path, and nothing is stored only to be read back.
// (kDirectGap; FastSprings::add_run takes this path for such runs.)

// Springs t = 0 .. count - 1 of a run (inputs as in forces_of_run), their forces added to
// the upper ends (f_upper[c n + t], if ToUpper) and the lower ends (f_lower[c n + t], if ToLower):
// +f1 to the i end and -f1 to the j end. f_upper and f_lower point into the same array,
// kDirectGap or more apart, which is why they are not restrict. `flatten` asks for the kernel
// inlined at link time, as in forces_of_run: for these instances GCC declines otherwise.
//
// Masked: one whole vector (count is kVectorLanes<S>), of which only springs t >= from add their
// shares. Springs t < from still get their kernel, and their ends take a zero that changes
// nothing: -0.0 added to the i end and +0.0 subtracted from the j end leave any value as it was,
// bit for bit (+0.0 and -0.0 included, where +0.0 added would turn a -0.0 into +0.0). That is how
// a run's last, partial vector is finished (add_run_direct): a whole vector ending at the run's
// end, whose first lanes the vectors before it have done, in one vector pass instead of a scalar
// loop per component.
template <class S, bool Uniform, bool UpperIsJ, bool ToUpper, bool ToLower, bool Masked = false>
[[gnu::noinline, gnu::flatten]] void run_kernel_direct(
    Index count, Index nx, Index nv, Index n, const S* __restrict x1, const S* __restrict x2,
    const S* __restrict v1, const S* __restrict v2, const S* __restrict ks, const S* __restrict kd,
    const S* __restrict l0, S* f_upper, S* f_lower, Index from = 0) {
  using V = Vec3Of<S>;
  // No two springs the compiler takes at once touch the same particle (see kDirectGap). A
  // masked pass is one whole vector, its count known here: one vector instruction a step of the
  // kernel, where a count read at run time had GCC take the springs one at a time.
  const Index springs = Masked ? kVectorLanes<S> : count;
  CLOTHLAB_INDEPENDENT_ITERATIONS
  for (Index t = 0; t < springs; ++t) {
    const V f1 =
        spring_kernel(V(x1[t], x1[nx + t], x1[2 * nx + t]), V(x2[t], x2[nx + t], x2[2 * nx + t]),
                      V(v1[t], v1[nv + t], v1[2 * nv + t]), V(v2[t], v2[nv + t], v2[2 * nv + t]),
                      ks[Uniform ? 0 : t], kd[Uniform ? 0 : t], l0[t]);
    // The i end gets +f1, the j end -f1. Component by component, written out: the compiler
    // keeps f1 in registers only if no loop index picks its components.
    S* const f_i = UpperIsJ ? f_lower : f_upper;
    S* const f_j = UpperIsJ ? f_upper : f_lower;
    if constexpr (Masked) {
      const bool on = t >= from;
      if constexpr (UpperIsJ ? ToLower : ToUpper) {
        f_i[t] += on ? f1.x() : S(-0.0);
        f_i[n + t] += on ? f1.y() : S(-0.0);
        f_i[2 * n + t] += on ? f1.z() : S(-0.0);
      }
      if constexpr (UpperIsJ ? ToUpper : ToLower) {
        f_j[t] -= on ? f1.x() : S(0.0);
        f_j[n + t] -= on ? f1.y() : S(0.0);
        f_j[2 * n + t] -= on ? f1.z() : S(0.0);
      }
      continue;
    }
    if constexpr (UpperIsJ ? ToLower : ToUpper) {
      f_i[t] += f1.x();
      f_i[n + t] += f1.y();
      f_i[2 * n + t] += f1.z();
    }
    if constexpr (UpperIsJ ? ToUpper : ToLower) {
      f_j[t] -= f1.x();
      f_j[n + t] -= f1.y();
      f_j[2 * n + t] -= f1.z();
    }
  }
  CLOTHLAB_INDEPENDENT_ITERATIONS_END
}

// f[c][t] += f1[c][t] (add) or -= (subtract), for t = 0 .. count - 1 and each component c;
// f's components are n apart, f1's kChunk apart. In whole vectors (add_to_row, vectorise.hpp).
template <class S>
void add_shares(Index count, Index n, const S* __restrict f1, S* __restrict f, bool add) {
  for (int c = 0; c < 3; ++c) {
    if (add) {
      add_to_row<S, true>(count, f1 + c * kChunk, f + c * n);
    } else {
      add_to_row<S, false>(count, f1 + c * kChunk, f + c * n);
    }
  }
}

// A particle that is the upper end of spring t and the lower end of spring t + gap of the same
// chunk takes both shares in one visit, upper first: f[c][t] = (f[c][t] -+ f1[c][t]) +- f1[c][t +
// gap], for t = 0 .. count - 1 (- then + when the upper ends are the j ends). Two passes would
// read back, one to three places over, a value just stored by a vector instruction, which the
// processor cannot forward from its store buffer: a stall on every load. f's components are n
// apart, f1's `stride` (kChunk in add_run's buffer).
//
// In whole vectors, as add_to_row (vectorise.hpp): the last vector's values made from those
// before the loop, stored after it.
template <class S, bool UpperIsJ>
void add_both_shares_of(Index count, Index n, Index gap, const S* __restrict f1, S* __restrict f,
                        Index stride) {
  constexpr Index kLanes = kVectorLanes<S>;
  const auto both = [](S fc, S up, S lo) { return UpperIsJ ? (fc - up) + lo : (fc + up) - lo; };
  const bool tail = kWholeVectorEnds<S> && count > kLanes && count % kLanes != 0;
  const Index last = count - kLanes, whole = count - count % kLanes;
  for (int c = 0; c < 3; ++c) {
    S* __restrict fc = f + c * n;
    const S* __restrict up = f1 + c * stride;
    const S* __restrict lo = up + gap;
    if (!tail) {
      for (Index t = 0; t < count; ++t)
        fc[t] = both(fc[t], up[t], lo[t]);
      continue;
    }
    S end[kLanes];
    for (Index l = 0; l < kLanes; ++l)
      end[l] = both(fc[last + l], up[last + l], lo[last + l]);
    for (Index t = 0; t < whole; ++t)
      fc[t] = both(fc[t], up[t], lo[t]);
    for (Index l = 0; l < kLanes; ++l)
      fc[last + l] = end[l];
  }
}
template <class S>
void add_both_shares(Index count, Index n, Index gap, const S* f1, S* f, bool upper_is_j,
                     Index stride = kChunk) {
  (upper_is_j ? add_both_shares_of<S, true> : add_both_shares_of<S, false>)(count, n, gap, f1, f,
                                                                            stride);
}

}  // namespace

namespace {

// The springs of a run, or of one row of a stencil, as the loops below read them: spring t joins
// particles i0 + t and j0 + t, with constants ks[t], kd[t] (ks[0] and kd[0] if uniform) and
// l0[t], in the copies' scalar S.
template <class S>
struct RunView {
  Index i0, j0, length;
  const S *ks, *kd, *l0;
  bool uniform;
};

// SpringDampers::add_forces on the copies, stencil by stencil and run by run (SpringLayout). The
// layout is cut again whenever the set's ends or constants change (SpringSet::version), or, while
// it holds stencils, a rest length (SpringSet::rest_version): both are checked before every
// evaluation. S: the copies' scalar (double: the fast path; float: the float room).
template <class S>
class FastSprings final : public FastForceOf<S> {
 public:
  using SoA = SoA3Of<S>;

 public:
  explicit FastSprings(const SpringDampers& springs) : springs_(springs) {}

  bool prepare(const Particles& /*p*/) override {
    const SpringSet& s = springs_.springs();
    if (!built_ || version_ != s.version()) {
      runs_ = spring_runs(s);
      layout_ = spring_layout(s, runs_);
      version_ = s.version();
      rest_version_ = s.rest_version();
      built_ = true;
      round_constants();
    } else if (rest_version_ != s.rest_version()) {
      // A rest length moved: the springs it left no longer belong in a stencil. Runs read the
      // set's rest lengths where they are, so a layout without stencils stands as it is.
      if (!layout_.stencils.empty()) layout_ = spring_layout(s, runs_);
      rest_version_ = s.rest_version();
      round_constants();
    }
    // Runs of a few springs cost more in bookkeeping than they save: such a set (springs given
    // one by one, or shuffled) is left to add_forces. The float room has no add_forces in float
    // to leave it to: there every set goes run by run, runs of one spring included.
    constexpr size_t kMinMeanRun = 8;
    return std::is_same_v<S, float> || s.size() >= kMinMeanRun * runs_.size();
  }

  void add(const Particles& /*p*/, const SoA& x, const SoA& v, SoA& f, Index begin,
           Index end) const override {
    // In the set's order: each stencil after the runs that come before it.
    size_t next = 0;
    for (size_t k = 0; k < layout_.stencils.size(); ++k) {
      for (; next < layout_.stencils[k].runs_before; ++next)
        add_run(view(layout_.runs[next]), begin, end, x, v, f);
      add_stencil(k, begin, end, x, v, f);
    }
    for (; next < layout_.runs.size(); ++next)
      add_run(view(layout_.runs[next]), begin, end, x, v, f);
  }

  size_t stencil_springs() const override { return layout_.stencil_springs(); }

  // The springs' energy as SpringDampers::potential_energy sums it: each spring's energy in the
  // set's order, block by block (kEnergyBlock), and the blocks' sums in order. The energies come
  // run by run, several springs an instruction (energies_of_run), into energies_, each thread of
  // the world the springs of its own range of the set (a run cut where a range ends: each
  // spring's energy is the same bits in any lane); each thread then sums the blocks that lie
  // whole in its range, in order, as the readable loop does. This thread sums the blocks that
  // two ranges share, and then the blocks' sums in order: the same bits. On doubles only: the
  // energies the guard checks are the engine's.
  bool potential_energy(const World& world, const Matrix3X& x, double& energy) override {
    if constexpr (!std::is_same_v<S, double>) {
      return false;
    } else {
      if (!prepare(world.particles)) return false;  // runs too short to pay: the effect's loop
      const SpringSet& s = springs_.springs();
      const Index n = static_cast<Index>(s.size());
      const Index block = static_cast<Index>(kEnergyBlock);
      const Index blocks = (n + block - 1) / block;
      energies_.resize(static_cast<size_t>(blocks * block));
      std::fill(energies_.begin() + n, energies_.end(), 0.0);  // the last block's tail
      block_sums_.assign(static_cast<size_t>(blocks), 0.0);
      block_summed_.assign(static_cast<size_t>(blocks), 0);
      // Block b's sum, its springs' energies added in order.
      const auto sum_block = [&](Index b) {
        double sum = 0.0;
        for (Index k = b * block; k < std::min(n, (b + 1) * block); ++k)
          sum += energies_[static_cast<size_t>(k)];
        block_sums_[static_cast<size_t>(b)] = sum;
        block_summed_[static_cast<size_t>(b)] = 1;
      };
      // Blocks [b0, b1), each in order as sum_block does: eight blocks at a time, eight sums that
      // do not wait on each other (one addition after another is the loop's whole cost), then
      // four, two and one. The last block, if short, counts as whole: its tail holds +0.0,
      // which leaves a sum as it was (a sum of energies that starts at +0.0 is never -0.0).
      const auto sum_blocks = [&](Index b0, Index b1) {
        const auto group = [&](Index b, Index count, auto sum_group) {
          for (; b + count <= b1; b += count) {
            sum_group(energies_.data() + b * block, block, block_sums_.data() + b);
            std::fill_n(block_summed_.begin() + b, count, 1);
          }
          return b;
        };
        Index b = group(b0, 8, sums_of_blocks<8>);
        b = group(b, 4, sums_of_blocks<4>);
        b = group(b, 2, sums_of_blocks<2>);
        group(b, 1, sums_of_blocks<1>);
      };
      world.for_items(n, [&](Index begin, Index end) {
        // The runs cover the set in its order: the first that ends after `begin`, and on.
        auto run = std::partition_point(runs_.begin(), runs_.end(), [&](const SpringRun& r) {
          return static_cast<Index>(r.k0) + r.length <= begin;
        });
        for (; run != runs_.end() && static_cast<Index>(run->k0) < end; ++run) {
          const Index k0 = std::max(begin, static_cast<Index>(run->k0));
          const Index k1 = std::min(end, static_cast<Index>(run->k0) + run->length);
          const Index t = k0 - static_cast<Index>(run->k0);  // the first spring, along the run
          energies_of_run(k1 - k0, x.data() + 3 * (run->i0 + t), x.data() + 3 * (run->j0 + t),
                          s.ks().data() + k0, s.l0().data() + k0, energies_.data() + k0);
        }
        // The blocks whole in [begin, end) (the last block ends at n).
        const Index b0 = (begin + block - 1) / block;
        Index b1 = b0;
        while (b1 * block < end && std::min(n, (b1 + 1) * block) <= end)
          ++b1;
        sum_blocks(b0, b1);
      });
      double sum = 0.0;
      for (Index b = 0; b < blocks; ++b) {
        if (!block_summed_[static_cast<size_t>(b)]) sum_block(b);  // one cut by two ranges
        sum += block_sums_[static_cast<size_t>(b)];
      }
      energy = sum;
      return true;
    }
  }

 private:
  // The float room's constants: the set's ks, kd and l0 and each stencil's, rounded to float
  // once, when the set or a rest length changes (prepare), not as each spring reads them: a loop
  // that reads doubles beside its floats takes as few floats an instruction as doubles (two in
  // the page's WebAssembly, where its floats would take four). Rounded once or as read, a
  // constant is the same float. The fast path (double) reads the set's own arrays.
  struct Rounded {
    std::vector<S> ks, kd, l0;
    std::vector<std::array<S, 2>> stencil_k;  // each stencil's ks and kd
    std::vector<std::vector<S>> stencil_l0;   // and its rows of rest lengths
  };
  void round_constants() {
    if constexpr (!std::is_same_v<S, double>) {
      const SpringSet& s = springs_.springs();
      const auto rounded = [](const std::vector<double>& a) {
        return std::vector<S>(a.begin(), a.end());
      };
      rounded_.ks = rounded(s.ks());
      rounded_.kd = rounded(s.kd());
      rounded_.l0 = rounded(s.l0());
      rounded_.stencil_k.clear();
      rounded_.stencil_l0.clear();
      for (const SpringStencil& stencil : layout_.stencils) {
        rounded_.stencil_k.push_back({static_cast<S>(stencil.ks), static_cast<S>(stencil.kd)});
        rounded_.stencil_l0.push_back(rounded(stencil.l0));
      }
    }
  }

  RunView<S> view(const SpringRun& run) const {
    if constexpr (std::is_same_v<S, double>) {
      const SpringSet& s = springs_.springs();
      return {run.i0,
              run.j0,
              run.length,
              s.ks().data() + run.k0,
              s.kd().data() + run.k0,
              s.l0().data() + run.k0,
              run.uniform};
    } else {
      return {run.i0,
              run.j0,
              run.length,
              rounded_.ks.data() + run.k0,
              rounded_.kd.data() + run.k0,
              rounded_.l0.data() + run.k0,
              run.uniform};
    }
  }
  // Adds the forces of the springs of `run` on the particles [p_begin, p_end) to f.
  void add_run(const RunView<S>& run, Index p_begin, Index p_end, const SoA& x, const SoA& v,
               SoA& f) const;
  // The same for a run whose ends are kDirectGap or more apart, without the buffer: springs
  // [up_begin, up_end) have their upper end in range, [lo_begin, lo_end) their lower end.
  void add_run_direct(const RunView<S>& run, Index up_begin, Index up_end, Index lo_begin,
                      Index lo_end, const SoA& x, const SoA& v, SoA& f) const;
  // The same for the rows of a stencil with an end in range, row after row: the rows come in
  // the set's order, and a particle meets them in the order add_forces adds them.
  void add_stencil(size_t index, Index p_begin, Index p_end, const SoA& x, const SoA& v,
                   SoA& f) const {
    const SpringStencil& stencil = layout_.stencils[index];
    const S *ks, *kd, *l0;  // the stencil's constants: its own, or the float room's
    if constexpr (std::is_same_v<S, double>) {
      ks = &stencil.ks;
      kd = &stencil.kd;
      l0 = stencil.l0.data();
    } else {
      ks = &rounded_.stencil_k[index][0];
      kd = &rounded_.stencil_k[index][1];
      l0 = rounded_.stencil_l0[index].data();
    }
    const Index lower = std::min(stencil.i0, stencil.j0), upper = std::max(stencil.i0, stencil.j0);
    // Row r's ends lie in [lower + r stride, upper + r stride + length): the rows that reach
    // [p_begin, p_end), or a row more (add_run finds it has nothing there).
    const Index r0 = std::max<Index>(0, (p_begin - upper - stencil.length) / stencil.stride);
    const Index r1 =
        p_end <= lower ? 0 : std::min(stencil.rows, (p_end - lower) / stencil.stride + 1);
    const auto row = [&](Index r) {
      const Index shift = r * stencil.stride;
      add_run({stencil.i0 + shift, stencil.j0 + shift, stencil.length, ks, kd,
               l0 + stencil.row_l0[static_cast<size_t>(r)], true},
              p_begin, p_end, x, v, f);
    };
    // Rows [whole0, whole1) lie wholly in range, both ends of every spring: add_rows_direct
    // (springs that go straight to their ends, kDirectGap) or add_rows_buffered (a row that fits
    // one chunk) takes them without the bookkeeping add_run does for a row that may be cut. Rows
    // in order, so the same sums.
    const bool direct = upper - lower >= kDirectGap;
    Index whole0 = r1, whole1 = r1;
    if ((direct || stencil.length <= kChunk) && r0 < r1) {
      const Index first =
          p_begin <= lower ? 0 : (p_begin - lower + stencil.stride - 1) / stencil.stride;
      const Index past = p_end < upper + stencil.length
                             ? 0
                             : (p_end - upper - stencil.length) / stencil.stride + 1;
      whole0 = std::clamp(first, r0, r1);
      whole1 = std::clamp(past, whole0, r1);
    }
    for (Index r = r0; r < whole0; ++r)
      row(r);
    if (whole0 < whole1 && direct) add_rows_direct(stencil, ks, kd, l0, whole0, whole1, x, v, f);
    if (whole0 < whole1 && !direct) add_rows_buffered(stencil, ks, kd, l0, whole0, whole1, x, v, f);
    for (Index r = whole1; r < r1; ++r)
      row(r);
  }
  // Rows [r_begin, r_end) of a stencil whose springs go straight to their ends, every end in the
  // thread's range: each row as add_run_direct takes a row wholly in range, the whole vectors and
  // then the last, masked.
  void add_rows_direct(const SpringStencil& stencil, const S* ks, const S* kd, const S* l0,
                       Index r_begin, Index r_end, const SoA& x, const SoA& v, SoA& f) const;
  // The same for a stencil whose springs' ends are fewer than kDirectGap apart, rows of at most
  // kChunk springs: each row as add_run takes a row wholly in range, in one chunk.
  void add_rows_buffered(const SpringStencil& stencil, const S* ks, const S* kd, const S* l0,
                         Index r_begin, Index r_end, const SoA& x, const SoA& v, SoA& f) const;

  const SpringDampers& springs_;
  std::vector<SpringRun> runs_;  // the set's runs, as spring_runs cuts them
  SpringLayout layout_;          // and as the fast path takes them
  bool built_ = false;
  unsigned long version_ = 0, rest_version_ = 0;
  std::vector<double> energies_;    // potential_energy's, one a spring in the set's order
  std::vector<double> block_sums_;  // and its blocks' sums (kEnergyBlock springs a block),
  std::vector<char> block_summed_;  // each marked once summed
  Rounded rounded_;                 // the float room's constants (empty on doubles)
};

template <class S>
void FastSprings<S>::add_run(const RunView<S>& run, Index p_begin, Index p_end, const SoA& x,
                             const SoA& v, SoA& f) const {
  const Index n = f.cols();  // the stride of f's rows (of x's: x.cols(), of v's: v.cols())
  const Index lower = std::min(run.i0, run.j0), upper = std::max(run.i0, run.j0);
  const auto in_run = [&](Index t) { return std::clamp<Index>(t, 0, run.length); };
  // The springs with an upper end in [p_begin, p_end), and those with a lower end there.
  const Index up_begin = in_run(p_begin - upper), up_end = in_run(p_end - upper);
  const Index lo_begin = in_run(p_begin - lower), lo_end = in_run(p_end - lower);
  if (up_begin == up_end && lo_begin == lo_end) return;
  if (upper - lower >= kDirectGap) {
    add_run_direct(run, up_begin, up_end, lo_begin, lo_end, x, v, f);
    return;
  }
  const Index first = up_begin < up_end ? up_begin : lo_begin;
  const Index last = lo_begin < lo_end ? lo_end : up_end;
  const bool upper_is_j = run.j0 > run.i0;
  S f1[3 * kChunk];
  for (Index c0 = first; c0 < last; c0 += kChunk) {
    const Index c1 = std::min(c0 + kChunk, last);
    const Index k = run.uniform ? 0 : c0;  // ks and kd of spring c0 (a uniform run's: of 0)
    (run.uniform ? forces_in_vectors<S, true>
                 : forces_in_vectors<S, false>)(c1 - c0, x.cols(), v.cols(), x.data() + run.i0 + c0,
                                                x.data() + run.j0 + c0, v.data() + run.i0 + c0,
                                                v.data() + run.j0 + c0, run.ks + k, run.kd + k,
                                                run.l0 + c0, f1, f1 + kChunk, f1 + 2 * kChunk);
    // Springs [u0, u1) of the chunk give upper ends their shares, [l0, l1) lower ends theirs.
    // Upper end upper + t is lower end lower + t + gap: where both fall in this chunk, that
    // particle takes both at once (upper first); the others take theirs one pass at a time.
    const Index gap = upper - lower;
    const Index u0 = std::max(c0, up_begin), u1 = std::min(c1, up_end);
    const Index l0 = std::max(c0, lo_begin), l1 = std::min(c1, lo_end);
    const Index both0 = std::max(u0, l0 - gap), both1 = std::max(both0, std::min(u1, l1 - gap));
    S* const f_upper = f.data() + upper;
    S* const f_lower = f.data() + lower;
    const auto upper_only = [&](Index t0, Index t1) {
      if (t0 < t1) add_shares(t1 - t0, n, f1 + (t0 - c0), f_upper + t0, !upper_is_j);
    };
    const auto lower_only = [&](Index t0, Index t1) {
      if (t0 < t1) add_shares(t1 - t0, n, f1 + (t0 - c0), f_lower + t0, upper_is_j);
    };
    if (both0 == both1) {
      upper_only(u0, u1);
      lower_only(l0, l1);
      continue;
    }
    // Distinct particles in each of the three: upper shares whose lower partner is in another
    // chunk, the particles with both, lower shares whose upper partner came in an earlier one.
    upper_only(u0, both0);
    upper_only(both1, u1);
    add_both_shares(both1 - both0, n, gap, f1 + (both0 - c0), f_upper + both0, upper_is_j);
    lower_only(l0, both0 + gap);
    lower_only(both1 + gap, l1);
  }
}

template <class S>
void FastSprings<S>::add_run_direct(const RunView<S>& run, Index up_begin, Index up_end,
                                    Index lo_begin, Index lo_end, const SoA& x, const SoA& v,
                                    SoA& f) const {
  const Index lower = std::min(run.i0, run.j0), upper = std::max(run.i0, run.j0);
  const bool upper_is_j = run.j0 > run.i0;
  // run_kernel_direct<S, Uniform, UpperIsJ, ToUpper, ToLower, Masked> by
  // [masked][uniform][upper_is_j][to_upper][to_lower].
  using Kernel = decltype(&run_kernel_direct<S, false, false, true, true>);
  static constexpr Kernel kernels[2][2][2][2][2] = {
      {{{{nullptr, run_kernel_direct<S, false, false, false, true>},
         {run_kernel_direct<S, false, false, true, false>,
          run_kernel_direct<S, false, false, true, true>}},
        {{nullptr, run_kernel_direct<S, false, true, false, true>},
         {run_kernel_direct<S, false, true, true, false>,
          run_kernel_direct<S, false, true, true, true>}}},
       {{{nullptr, run_kernel_direct<S, true, false, false, true>},
         {run_kernel_direct<S, true, false, true, false>,
          run_kernel_direct<S, true, false, true, true>}},
        {{nullptr, run_kernel_direct<S, true, true, false, true>},
         {run_kernel_direct<S, true, true, true, false>,
          run_kernel_direct<S, true, true, true, true>}}}},
      {{{{nullptr, run_kernel_direct<S, false, false, false, true, true>},
         {run_kernel_direct<S, false, false, true, false, true>,
          run_kernel_direct<S, false, false, true, true, true>}},
        {{nullptr, run_kernel_direct<S, false, true, false, true, true>},
         {run_kernel_direct<S, false, true, true, false, true>,
          run_kernel_direct<S, false, true, true, true, true>}}},
       {{{nullptr, run_kernel_direct<S, true, false, false, true, true>},
         {run_kernel_direct<S, true, false, true, false, true>,
          run_kernel_direct<S, true, false, true, true, true>}},
        {{nullptr, run_kernel_direct<S, true, true, false, true, true>},
         {run_kernel_direct<S, true, true, true, false, true>,
          run_kernel_direct<S, true, true, true, true, true>}}}}};
  // Springs [t0, t1) of the run, their forces added to the ends that are in range: the whole
  // vectors first; then, if the count is not a whole number of vectors, the last vector of the
  // range once more, masked so that only the springs past the whole vectors add their shares
  // (run_kernel_direct says why that leaves the others' sums as they were; forces_in_vectors,
  // why a lane's f1 does not depend on the vector it is in). No particle is an end of two
  // springs of one vector (fewer springs than kDirectGap), so the same shares in the same
  // order as one spring at a time.
  const auto springs = [&](Index t0, Index t1, bool to_upper, bool to_lower) {
    if (t0 >= t1) return;
    constexpr Index kLanes = kVectorLanes<S>;
    static_assert(kLanes <= kDirectGap);
    const Index rest = kWholeVectorEnds<S> && t1 - t0 > kLanes ? (t1 - t0) % kLanes : 0;
    const auto run_from = [&](bool masked, Index first, Index last, Index from) {
      const Index k = run.uniform ? 0 : first;  // ks and kd of spring first (a uniform run's: of 0)
      kernels[masked][run.uniform][upper_is_j][to_upper][to_lower](
          last - first, x.cols(), v.cols(), f.cols(), x.data() + run.i0 + first,
          x.data() + run.j0 + first, v.data() + run.i0 + first, v.data() + run.j0 + first,
          run.ks + k, run.kd + k, run.l0 + first, f.data() + upper + first,
          f.data() + lower + first, from);
    };
    run_from(false, t0, t1 - rest, 0);
    if (rest > 0) run_from(true, t1 - kLanes, t1, kLanes - rest);
  };
  // Spring t has its upper end in range for t in [up_begin, up_end) and its lower end for t in
  // [lo_begin, lo_end), the same interval shifted by the gap (or clamped to the run). In the
  // order of t: springs with only their upper end in range, then both, then only the lower.
  const Index both_begin = std::max(up_begin, lo_begin), both_end = std::min(up_end, lo_end);
  springs(up_begin, std::min(up_end, lo_begin), true, false);
  springs(both_begin, both_end, true, true);
  springs(std::max(up_end, lo_begin), lo_end, false, true);
}

template <class S>
void FastSprings<S>::add_rows_direct(const SpringStencil& stencil, const S* ks, const S* kd,
                                     const S* l0, Index r_begin, Index r_end, const SoA& x,
                                     const SoA& v, SoA& f) const {
  const Index lower = std::min(stencil.i0, stencil.j0), upper = std::max(stencil.i0, stencil.j0);
  const bool upper_is_j = stencil.j0 > stencil.i0;
  const auto kernel = upper_is_j ? run_kernel_direct<S, true, true, true, true>
                                 : run_kernel_direct<S, true, false, true, true>;
  const auto masked = upper_is_j ? run_kernel_direct<S, true, true, true, true, true>
                                 : run_kernel_direct<S, true, false, true, true, true>;
  constexpr Index kLanes = kVectorLanes<S>;
  const Index length = stencil.length;
  const Index rest = kWholeVectorEnds<S> && length > kLanes ? length % kLanes : 0;
  for (Index r = r_begin; r < r_end; ++r) {
    const Index shift = r * stencil.stride;
    const S* const row_l0 = l0 + stencil.row_l0[static_cast<size_t>(r)];
    // Springs [first, last) of row r (as add_run_direct's run_from, on a uniform run).
    const auto springs = [&](auto kernel_of, Index first, Index last, Index from) {
      const Index i = stencil.i0 + shift + first, j = stencil.j0 + shift + first;
      kernel_of(last - first, x.cols(), v.cols(), f.cols(), x.data() + i, x.data() + j,
                v.data() + i, v.data() + j, ks, kd, row_l0 + first,
                f.data() + upper + shift + first, f.data() + lower + shift + first, from);
    };
    springs(kernel, 0, length - rest, 0);
    if (rest > 0) springs(masked, length - kLanes, length, kLanes - rest);
  }
}

template <class S>
void FastSprings<S>::add_rows_buffered(const SpringStencil& stencil, const S* ks, const S* kd,
                                       const S* l0, Index r_begin, Index r_end, const SoA& x,
                                       const SoA& v, SoA& f) const {
  const Index n = f.cols();
  const Index lower = std::min(stencil.i0, stencil.j0), upper = std::max(stencil.i0, stencil.j0);
  const Index gap = upper - lower, length = stencil.length;
  const bool upper_is_j = stencil.j0 > stencil.i0;
  // Each component's forces with kDirectGap places on either side (gap < kDirectGap), which hold
  // zeros that leave a particle as it was: the upper share of a spring before the row's first
  // (-f1 on a j end, +f1 on an i end: +0.0 subtracted, -0.0 added) and the lower share of one
  // after its last (-0.0 added, +0.0 subtracted). Then every particle of the row, lower + q for q
  // in [0, length + gap), takes both its shares in one visit, upper first, as add_both_shares
  // does: f = (f -+ f1[q - gap]) +- f1[q]. Those with one share take the other as a zero that
  // changes no bit (+0.0 and -0.0 included), so the sums are add_run's.
  constexpr Index kPad = kDirectGap, kStride = kChunk + 2 * kPad;
  S buffer[3 * kStride];
  S* const f1 = buffer + kPad;  // component c of spring t at f1[c kStride + t]
  const S before = upper_is_j ? S(0.0) : S(-0.0), after = upper_is_j ? S(-0.0) : S(0.0);
  for (int c = 0; c < 3; ++c) {
    for (Index t = 0; t < gap; ++t) {
      f1[c * kStride - gap + t] = before;
      f1[c * kStride + length + t] = after;
    }
  }
  for (Index r = r_begin; r < r_end; ++r) {
    const Index shift = r * stencil.stride;
    const Index i = stencil.i0 + shift, j = stencil.j0 + shift;
    forces_in_vectors<S, true>(length, x.cols(), v.cols(), x.data() + i, x.data() + j, v.data() + i,
                               v.data() + j, ks, kd, l0 + stencil.row_l0[static_cast<size_t>(r)],
                               f1, f1 + kStride, f1 + 2 * kStride);
    add_both_shares(length + gap, n, gap, f1 - gap, f.data() + lower + shift, upper_is_j, kStride);
  }
}

}  // namespace

template <class Scalar>
std::unique_ptr<FastForceOf<Scalar>> fast_springs(const SpringDampers& springs) {
  return std::make_unique<FastSprings<Scalar>>(springs);
}
template std::unique_ptr<FastForceOf<double>> fast_springs(const SpringDampers&);
template std::unique_ptr<FastForceOf<float>> fast_springs(const SpringDampers&);

}  // namespace clothlab::fast
