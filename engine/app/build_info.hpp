// build_info.hpp: which exercise kernels this program was linked with, and how.
#pragma once

namespace clothlab::app {
extern const char* const kKernels;     // "reference" (solutions/) or "student" (exercises/)
extern const bool kLinkTimeOptimised;  // kernels inlined into the engine at link time
}  // namespace clothlab::app
