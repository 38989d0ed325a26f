// vectorise.hpp: the hint before a loop whose iterations touch no common particle, and how the
// fast path's loops finish a row that whole vectors do not fill.
//
// The compiler cannot see that the particles a loop reads and writes through indices are
// distinct for distinct iterations (a run of springs kDirectGap or more apart, springs.cpp; the
// constraints of one colour, xpbd.cpp); CLOTHLAB_INDEPENDENT_ITERATIONS before the loop says so,
// and CLOTHLAB_INDEPENDENT_ITERATIONS_END after it. Clang says so when it cannot vectorise the
// loop anyway, which is the case whenever the kernel is not inlined (a build without link-time
// optimisation): no reason for a warning. A WebAssembly module without SIMD (engine/web/) has
// nothing to vectorise with, and there the link-time optimiser would say so past the pragma: no
// hint at all.
#pragma once

#include "clothlab/core/types.hpp"

#if defined(__wasm__) && !defined(__wasm_simd128__)
#define CLOTHLAB_INDEPENDENT_ITERATIONS
#define CLOTHLAB_INDEPENDENT_ITERATIONS_END
#elif defined(__clang__)
#define CLOTHLAB_INDEPENDENT_ITERATIONS                                                  \
  _Pragma("clang diagnostic push") _Pragma("clang diagnostic ignored \"-Wpass-failed\"") \
      _Pragma("clang loop vectorize(assume_safety)")
#define CLOTHLAB_INDEPENDENT_ITERATIONS_END _Pragma("clang diagnostic pop")
#elif defined(__GNUC__)
#define CLOTHLAB_INDEPENDENT_ITERATIONS _Pragma("GCC ivdep")
#define CLOTHLAB_INDEPENDENT_ITERATIONS_END
#else
#define CLOTHLAB_INDEPENDENT_ITERATIONS
#define CLOTHLAB_INDEPENDENT_ITERATIONS_END
#endif

namespace clothlab::fast {

// How many values of S one vector instruction of this build takes: 64 bytes with AVX-512, 32
// with AVX, 16 otherwise (SSE2, WebAssembly SIMD). A loop whose count is not a multiple of it
// leaves a remainder that the compiler finishes with narrower vectors and then one value at a
// time; where a vector holds more than two values, the loops of springs.cpp and aerodynamics.cpp
// finish theirs instead with one more full vector (forces_in_vectors, run_kernel_direct's masked
// pass, shares_in_vectors and add_to_row below say how, and why the bits are the same).
#if defined(__AVX512F__)
inline constexpr Index kVectorBytes = 64;
#elif defined(__AVX__)
inline constexpr Index kVectorBytes = 32;
#else
inline constexpr Index kVectorBytes = 16;
#endif
template <class S>
inline constexpr Index kVectorLanes = kVectorBytes / static_cast<Index>(sizeof(S));

// Whether loops here finish their remainder in whole vectors. With vectors of two lanes (SSE2;
// WebAssembly SIMD, whose doubles the lesson pages take two at a time) the remainder is one value
// at most, which one more vector could only cost more than: there the compiler's remainder stays.
// (In the page, the two measured alike within their spread: SPEED.md.)
template <class S>
inline constexpr bool kWholeVectorEnds = kVectorLanes<S> > 2;

// dst[i] = dst[i] + src[i] (Add) or dst[i] - src[i] (!Add), i = 0 .. count - 1, in whole vectors:
// the last vector's sums are made first, from the values before the loop (its lanes that overlap
// the loop's last vector compute what the loop computes there, the same operation on the same
// two numbers), then the loop runs up to the last multiple of the vector's width, and then those
// sums are stored. No value is added twice, none is read back just after a vector store over it
// (a load the processor could not forward from its store buffer), and the compiler's one-at-a-
// time remainder is never taken, except by a row shorter than one vector.
template <class S, bool Add>
void add_to_row(Index count, const S* __restrict src, S* __restrict dst) {
  constexpr Index kLanes = kVectorLanes<S>;
  if (!kWholeVectorEnds<S> || count <= kLanes || count % kLanes == 0) {
    for (Index i = 0; i < count; ++i)
      dst[i] = Add ? dst[i] + src[i] : dst[i] - src[i];
    return;
  }
  const Index last = count - kLanes, whole = count - count % kLanes;
  S tail[kLanes];
  for (Index l = 0; l < kLanes; ++l)
    tail[l] = Add ? dst[last + l] + src[last + l] : dst[last + l] - src[last + l];
  for (Index i = 0; i < whole; ++i)
    dst[i] = Add ? dst[i] + src[i] : dst[i] - src[i];
  for (Index l = 0; l < kLanes; ++l)
    dst[last + l] = tail[l];
}

}  // namespace clothlab::fast
