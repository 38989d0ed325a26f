// build_info.cpp: compiled once per program (see clothlab_program in engine/CMakeLists.txt).
#include "app/build_info.hpp"

namespace clothlab::app {
const char* const kKernels = CLOTHLAB_IMPL;
const bool kLinkTimeOptimised = CLOTHLAB_LTO;
}  // namespace clothlab::app
