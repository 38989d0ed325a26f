// vectorise.hpp: the hint before a loop whose iterations touch no common particle.
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
// time; where a vector holds more than two values, springs.cpp finishes a run's instead with
// one more full vector (forces_of_run's callers there say how, and why the bits are the same).
#if defined(__AVX512F__)
inline constexpr Index kVectorBytes = 64;
#elif defined(__AVX__)
inline constexpr Index kVectorBytes = 32;
#else
inline constexpr Index kVectorBytes = 16;
#endif
template <class S>
inline constexpr Index kVectorLanes = kVectorBytes / static_cast<Index>(sizeof(S));

}  // namespace clothlab::fast
