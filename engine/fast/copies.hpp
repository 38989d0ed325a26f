// copies.hpp: the fast engine's copies of the state, in a layout whose loops vectorise.
//
// The engine keeps each particle's x, y and z side by side (Matrix3X, one column a particle).
// The fast engine sums forces on copies stored as a structure of arrays (SoA3): the x components
// of every particle, then the y components, then the z components, each row contiguous. Column
// i is still particle i (s.col(i) is a Vec3 expression), but a loop over particles reads each
// component in memory order, which lets the compiler take four or eight particles at once. The
// copies have a few more columns than there are particles (padded_columns says why), so row c of
// s starts at s.data() + c * s.cols(): use s.cols() as the stride, never the number of particles.
// The float room (float_room.hpp) keeps the same copies in float: SoA3f, CopiesOf<float>.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>
#include <type_traits>

#include "clothlab/core/types.hpp"

#if defined(__wasm_simd128__)
#include <wasm_simd128.h>
#endif

namespace clothlab::fast {

// A structure of arrays that owns its storage (XPBD's and local/global's positions).
template <class Scalar>
using SoA3MatrixOf = Eigen::Matrix<Scalar, 3, Eigen::Dynamic, Eigen::RowMajor>;
using SoA3Matrix = SoA3MatrixOf<double>;

// The copies the force effects read and write: a view of storage laid out by the engine room
// (CopiesOf, ResidentOf). Row c starts at data() + c * cols(), as in an SoA3MatrixOf.
template <class Scalar>
using SoA3Of = Eigen::Map<SoA3MatrixOf<Scalar>>;
using SoA3 = SoA3Of<double>;
using SoA3f = SoA3Of<float>;

// Columns for n particles in a structure of arrays whose rows start `lines` cache lines apart,
// modulo 4 KiB. Rows n apart, for a cloth of 2^k particles, would start at the same place of a
// 4 KiB page, and the processor's first-level cache keeps only a few lines with the same such
// place: a spring's dozen inputs, all read at once, would evict each other.
template <class Scalar>
Index padded_columns(Index n, Index lines) {
  const Index period = 4096 / sizeof(Scalar), shift = lines * 64 / sizeof(Scalar);
  return n + ((shift - n) % period + period) % period;
}

// One allocation of the engine room's own, its start on a 4 KiB page, holding the arrays of one
// or more copies, each array's first row at a chosen cache line of a page.
//
// Why not Eigen's own storage: the project is compiled with Eigen's vector code off
// (EIGEN_DONT_VECTORIZE, sources.cmake), and then Eigen aligns what it allocates as malloc
// does, to 16 bytes. The spring loops read and write the copies 8 doubles (16 floats) an
// instruction, 64 bytes: an array 16 bytes past a cache line makes each of those accesses touch
// two lines.
// SPEED.md measured the double step about 8 % slower so (*The copies on cache lines*).
template <class Scalar>
class SoA3Pages {
 public:
  // Room for arrays of 3 rows of columns[k] each, array k's first row at cache line
  // start_line[k] (0 to 63) of a 4 KiB page; returns where each starts. The allocation is kept
  // if it has room; what the arrays held is not.
  template <size_t K>
  std::array<Scalar*, K> lay_out(const std::array<Index, K>& columns,
                                 const std::array<int, K>& start_line) {
    std::array<size_t, K> offset{};  // in bytes from the allocation's start
    size_t end = 0;
    for (size_t k = 0; k < K; ++k) {
      const size_t place = static_cast<size_t>(start_line[k] % 64) * 64;
      const size_t page = end / 4096 * 4096;
      offset[k] = page + place >= end ? page + place : page + 4096 + place;
      end = offset[k] + 3 * static_cast<size_t>(columns[k]) * sizeof(Scalar);
    }
    if (end > bytes_) {
      const size_t bytes = (end + 4095) / 4096 * 4096;
      data_.reset(static_cast<std::byte*>(std::aligned_alloc(4096, bytes)));
      if (!data_) throw std::bad_alloc();
      bytes_ = bytes;
    }
    std::array<Scalar*, K> at{};
    for (size_t k = 0; k < K; ++k)
      at[k] = reinterpret_cast<Scalar*>(data_.get() + offset[k]);
    return at;
  }

 private:
  struct Free {
    void operator()(std::byte* p) const { std::free(p); }
  };
  std::unique_ptr<std::byte, Free> data_;
  size_t bytes_ = 0;
};

// Where a copy's x, v and f start in a 4 KiB page, in cache lines (SoA3Pages::lay_out). With the
// rows' spacing (kRowSpacing), the 15 rows of a run of steps' two copies (ResidentOf: two of x
// and v, one f) each start at a line of their own, at least 2 lines from any other: no two of a
// spring's inputs or outputs share a place in the page by the layout's doing.
inline constexpr Index kRowSpacing[3] = {21, 7, 49};        // lines between the rows of x, v and f
inline constexpr std::array<int, 3> kFirstCopy{0, 38, 23};  // x, v, f
inline constexpr std::array<int, 2> kSecondCopy{5, 3};      // x, v

// The copies of positions, velocities and forces, kept by the fast engine between evaluations:
// views of storage laid out by the engine room (SoA3Pages). Not copyable: a copy's views would
// point into the original's storage.
template <class Scalar>
struct CopiesOf {
  SoA3Of<Scalar> x{nullptr, 3, 0}, v{nullptr, 3, 0}, f{nullptr, 3, 0};

  CopiesOf() = default;
  CopiesOf(const CopiesOf&) = delete;
  CopiesOf& operator=(const CopiesOf&) = delete;

  // Room for n particles in x, v and f, in storage of its own; the columns past n are padding.
  // What they held is kept only if n is unchanged.
  void resize(Index n) {
    if (n == n_) return;
    const auto at = pages_.lay_out(columns(n), kFirstCopy);
    bind(n, at[0], at[1], at[2]);
  }

  // The columns of x, v and f for n particles.
  static std::array<Index, 3> columns(Index n) {
    return {padded_columns<Scalar>(n, kRowSpacing[0]), padded_columns<Scalar>(n, kRowSpacing[1]),
            padded_columns<Scalar>(n, kRowSpacing[2])};
  }

  // x, v and f as views of arrays laid out elsewhere (ResidentOf), columns(n) each.
  void bind(Index n, Scalar* xs, Scalar* vs, Scalar* fs) {
    const auto c = columns(n);
    new (&x) SoA3Of<Scalar>(xs, 3, c[0]);
    new (&v) SoA3Of<Scalar>(vs, 3, c[1]);
    new (&f) SoA3Of<Scalar>(fs, 3, c[2]);
    n_ = n;
  }

 private:
  SoA3Pages<Scalar> pages_;
  Index n_ = -1;
};
using Copies = CopiesOf<double>;

// The two copies of the state a run of steps takes turns with (resident.hpp): the one a step
// reads, and the one its move writes, in one allocation. They share one f: a step clears and
// sums each block's forces there and its move reads them, and the next step clears them only
// once every thread has moved (the barrier between steps); the last step's forces stay.
template <class Scalar>
struct ResidentOf {
  CopiesOf<Scalar> a, b;

  // Room for n particles in both; what they held is kept only if n is unchanged.
  void resize(Index n) {
    if (n == n_) return;
    const auto c = CopiesOf<Scalar>::columns(n);
    const auto& sa = kFirstCopy;
    const auto& sb = kSecondCopy;
    const auto at = pages_.lay_out(std::array<Index, 5>{c[0], c[1], c[2], c[0], c[1]},
                                   std::array<int, 5>{sa[0], sa[1], sa[2], sb[0], sb[1]});
    a.bind(n, at[0], at[1], at[2]);
    b.bind(n, at[3], at[4], at[2]);
    n_ = n;
  }

 private:
  SoA3Pages<Scalar> pages_;
  Index n_ = -1;
};

// Particles [begin, end) of a (the engine's layout: x, y, z of particle i at a[3 i], a[3 i + 1],
// a[3 i + 2]) into s (rows `stride` apart). One pass, particle by particle: each particle's
// three components come from one cache line, where copying row by row would read a three times.
// Into float copies (the float room), each component is rounded to the nearest float.
template <class Scalar>
[[gnu::noinline]] void to_soa(Index begin, Index end, const double* __restrict a,
                              Scalar* __restrict s, Index stride) {
  for (Index i = begin; i < end; ++i) {
    s[i] = static_cast<Scalar>(a[3 * i]);
    s[stride + i] = static_cast<Scalar>(a[3 * i + 1]);
    s[2 * stride + i] = static_cast<Scalar>(a[3 * i + 2]);
  }
}

#if defined(__wasm_simd128__)
// The lesson pages' WebAssembly: to_soa_within's first particles, four at a time, by hand. Their
// twelve components are six pairs of doubles in memory; Clang, left to it, loads them one by one
// and rounds them to float one by one (a tenth of the page's float step). Here each pair is one
// load and one test (|a| <= bound, lane by lane, false for a NaN, as below), and the pairs are
// shuffled into a row each of x, y and z; into floats, each pair is rounded as one (the same
// rounding as a conversion of each). Returns the first particle it did not take; `within` is
// cleared if a component failed the test.
template <class Scalar>
Index to_soa_within_by_four(Index begin, Index end, const double* a, Scalar* s, Index stride,
                            double bound, bool& within) {
  const v128_t b = wasm_f64x2_splat(bound);
  v128_t ok = wasm_i64x2_splat(-1);
  Index i = begin;
  for (; i + 4 <= end; i += 4) {
    const double* p = a + 3 * i;
    // d0 = (x0, y0), d1 = (z0, x1), d2 = (y1, z1), d3 = (x2, y2), d4 = (z2, x3), d5 = (y3, z3)
    v128_t d[6];
    for (int k = 0; k < 6; ++k) {
      d[k] = wasm_v128_load(p + 2 * k);
      ok = wasm_v128_and(ok, wasm_f64x2_le(wasm_f64x2_abs(d[k]), b));
    }
    Scalar* const x = s + i;
    Scalar* const y = s + stride + i;
    Scalar* const z = s + 2 * stride + i;
    if constexpr (std::is_same_v<Scalar, double>) {
      wasm_v128_store(x, wasm_i64x2_shuffle(d[0], d[1], 0, 3));
      wasm_v128_store(x + 2, wasm_i64x2_shuffle(d[3], d[4], 0, 3));
      wasm_v128_store(y, wasm_i64x2_shuffle(d[0], d[2], 1, 2));
      wasm_v128_store(y + 2, wasm_i64x2_shuffle(d[3], d[5], 1, 2));
      wasm_v128_store(z, wasm_i64x2_shuffle(d[1], d[2], 0, 3));
      wasm_v128_store(z + 2, wasm_i64x2_shuffle(d[4], d[5], 0, 3));
    } else {
      static_assert(std::is_same_v<Scalar, float>);
      v128_t f[6];  // f[k] = (d[k] rounded, 0, 0)
      for (int k = 0; k < 6; ++k)
        f[k] = wasm_f32x4_demote_f64x2_zero(d[k]);
      const v128_t r0 = wasm_i32x4_shuffle(f[0], f[1], 0, 1, 4, 5);  // x0 y0 z0 x1
      const v128_t r1 = wasm_i32x4_shuffle(f[2], f[3], 0, 1, 4, 5);  // y1 z1 x2 y2
      const v128_t r2 = wasm_i32x4_shuffle(f[4], f[5], 0, 1, 4, 5);  // z2 x3 y3 z3
      const v128_t xs = wasm_i32x4_shuffle(r0, r1, 0, 3, 6, 7);      // x0 x1 x2 -
      const v128_t ys = wasm_i32x4_shuffle(r0, r1, 1, 4, 7, 7);      // y0 y1 y2 -
      const v128_t zs = wasm_i32x4_shuffle(r0, r1, 2, 5, 5, 5);      // z0 z1 - -
      wasm_v128_store(x, wasm_i32x4_shuffle(xs, r2, 0, 1, 2, 5));
      wasm_v128_store(y, wasm_i32x4_shuffle(ys, r2, 0, 1, 2, 6));
      wasm_v128_store(z, wasm_i32x4_shuffle(zs, r2, 0, 1, 4, 7));
    }
  }
  if (!wasm_i64x2_all_true(ok)) within = false;
  return i;
}

// The reverse, for the float room's move in the lesson pages (float_room.cpp): rows x, y and z of
// floats, particles 0 .. count - 1, into a (the engine's layout, x, y, z side by side) in
// doubles, four particles at a time. Each row's floats are widened a pair at a time (a float is
// exactly the double it is written as) and the pairs shuffled into the layout's order: six
// stores of two doubles where Clang, left to it, stored twelve one by one. With Test, each pair
// is tested as it is stored (|a| <= bound, lane by lane, false for a NaN: Guard::within's test)
// and `within` is cleared if one fails. Returns the first particle it did not take.
template <bool Test>
Index from_float_rows_by_four(Index count, const float* x, const float* y, const float* z,
                              double* a, double bound, bool& within) {
  const v128_t b = wasm_f64x2_splat(bound);
  v128_t ok = wasm_i64x2_splat(-1);
  Index i = 0;
  for (; i + 4 <= count; i += 4) {
    const v128_t xs = wasm_v128_load(x + i), ys = wasm_v128_load(y + i), zs = wasm_v128_load(z + i);
    // Each row's four floats as two pairs of doubles: (x0, x1), (x2, x3), ...
    const v128_t x01 = wasm_f64x2_promote_low_f32x4(xs);
    const v128_t x23 = wasm_f64x2_promote_low_f32x4(wasm_i32x4_shuffle(xs, xs, 2, 3, 2, 3));
    const v128_t y01 = wasm_f64x2_promote_low_f32x4(ys);
    const v128_t y23 = wasm_f64x2_promote_low_f32x4(wasm_i32x4_shuffle(ys, ys, 2, 3, 2, 3));
    const v128_t z01 = wasm_f64x2_promote_low_f32x4(zs);
    const v128_t z23 = wasm_f64x2_promote_low_f32x4(wasm_i32x4_shuffle(zs, zs, 2, 3, 2, 3));
    if constexpr (Test) {
      for (const v128_t d : {x01, x23, y01, y23, z01, z23})
        ok = wasm_v128_and(ok, wasm_f64x2_le(wasm_f64x2_abs(d), b));
    }
    double* const p = a + 3 * i;
    wasm_v128_store(p, wasm_i64x2_shuffle(x01, y01, 0, 2));       // x0 y0
    wasm_v128_store(p + 2, wasm_i64x2_shuffle(z01, x01, 0, 3));   // z0 x1
    wasm_v128_store(p + 4, wasm_i64x2_shuffle(y01, z01, 1, 3));   // y1 z1
    wasm_v128_store(p + 6, wasm_i64x2_shuffle(x23, y23, 0, 2));   // x2 y2
    wasm_v128_store(p + 8, wasm_i64x2_shuffle(z23, x23, 0, 3));   // z2 x3
    wasm_v128_store(p + 10, wasm_i64x2_shuffle(y23, z23, 1, 3));  // y3 z3
  }
  if (Test && !wasm_i64x2_all_true(ok)) within = false;
  return i;
}
#endif

// to_soa, and whether every component it copied is within bound: the guard's test
// (Guard::within, |a| <= bound, false for a NaN) on the values in hand, where a pass of its own
// would read them again. The test is on the doubles, before any rounding to float.
template <class Scalar>
[[gnu::noinline]] bool to_soa_within(Index begin, Index end, const double* __restrict a,
                                     Scalar* __restrict s, Index stride, double bound) {
  long outside = 0;
#if defined(__wasm_simd128__)
  bool within = true;
  begin = to_soa_within_by_four(begin, end, a, s, stride, bound, within);
  outside += !within;
#endif
  for (Index i = begin; i < end; ++i) {
    const double ax = a[3 * i], ay = a[3 * i + 1], az = a[3 * i + 2];
    s[i] = static_cast<Scalar>(ax);
    s[stride + i] = static_cast<Scalar>(ay);
    s[2 * stride + i] = static_cast<Scalar>(az);
    outside += !(std::abs(ax) <= bound) + !(std::abs(ay) <= bound) + !(std::abs(az) <= bound);
  }
  return outside == 0;
}

// The other way: particles [begin, end) of s back into a (from float, exactly).
template <class Scalar>
[[gnu::noinline]] void from_soa(Index begin, Index end, const Scalar* __restrict s, Index stride,
                                double* __restrict a) {
  for (Index i = begin; i < end; ++i) {
    a[3 * i] = s[i];
    a[3 * i + 1] = s[stride + i];
    a[3 * i + 2] = s[2 * stride + i];
  }
}

}  // namespace clothlab::fast
