// copies.hpp: the fast engine's copies of the state, in a layout whose loops vectorise.
//
// The engine keeps each particle's x, y and z side by side (Matrix3X, one column a particle).
// The fast engine sums forces on copies stored as a structure of arrays (SoA3): the x components
// of every particle, then the y components, then the z components, each row contiguous. Column
// i is still particle i (s.col(i) is a Vec3 expression), but a loop over particles reads each
// component in memory order, which lets the compiler take four or eight particles at once. The
// copies have a few more columns than there are particles (Copies::resize says why), so row c of
// s starts at s.data() + c * s.cols(): use s.cols() as the stride, never the number of particles.
// The float room (float_room.hpp) keeps the same copies in float: SoA3f, CopiesOf<float>.
#pragma once

#include <cmath>

#include "clothlab/core/types.hpp"

namespace clothlab::fast {

template <class Scalar>
using SoA3Of = Eigen::Matrix<Scalar, 3, Eigen::Dynamic, Eigen::RowMajor>;
using SoA3 = SoA3Of<double>;
using SoA3f = SoA3Of<float>;

// The copies of positions, velocities and forces, kept by the fast engine between evaluations.
template <class Scalar>
struct CopiesOf {
  SoA3Of<Scalar> x, v, f;

  // Room for n particles in x, v and f, each with rows spaced its own way: the columns past n
  // are padding. Rows n apart, for a cloth of 2^k particles, would start at the same place of a
  // 4 KiB page, and the processor's first-level cache keeps only 8 lines with the same such
  // place: a spring's dozen inputs, all read at once, would evict each other.
  void resize(Index n) {
    x.resize(3, padded(n, 21));
    v.resize(3, padded(n, 7));
    f.resize(3, padded(n, 49));
  }

  // Columns for n particles in a SoA3 whose rows start `lines` cache lines apart, modulo 4 KiB.
  static Index padded(Index n, Index lines) {
    const Index period = 4096 / sizeof(Scalar), shift = lines * 64 / sizeof(Scalar);
    return n + ((shift - n) % period + period) % period;
  }
};
using Copies = CopiesOf<double>;

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

// to_soa, and whether every component it copied is within bound: the guard's test
// (Guard::within, |a| <= bound, false for a NaN) on the values in hand, where a pass of its own
// would read them again. The test is on the doubles, before any rounding to float.
template <class Scalar>
[[gnu::noinline]] bool to_soa_within(Index begin, Index end, const double* __restrict a,
                                     Scalar* __restrict s, Index stride, double bound) {
  long outside = 0;
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
