// kernels_crash.hpp: how a grading binary says that the kernels' process died of a signal.
//
// The kernels run in a process of their own (tests/grade/harness/kernel_wire.hpp). When that
// process dies of signal N during a call, the call throws KernelsEnded
// (tests/grade/harness/kernel_client.cpp), whose text starts with kKernelsCrashed and the number:
// "crashed: signal 11 (in the exercise's code, ...)". The grader (cases.cpp) reads it back as the
// case crashing with that signal.
#pragma once

#include <string_view>

namespace clothlab::app::grading {

inline constexpr std::string_view kKernelsCrashed = "crashed: signal ";

}  // namespace clothlab::app::grading
