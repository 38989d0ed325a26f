// stop.hpp: a stop asked for from outside (Ctrl-C, a TERM) reaches the long loops of a step.
//
// A step is short for most scenes, and a run stops after it. But one step can take minutes (XPBD
// with thousands of substeps, [gravitation]'s n^2 / 2 pairs on a big cloth), and a user who asks
// a run to stop should not wait for it. So the loops that can be long call stop_point() between
// their pieces of work (a substep, an iteration, a sweep, a row of pairs). While a StopPoints
// lives on this thread (a run's step, its start-up work), stop_point() throws StepAbandoned once
// a stop was asked for: the step is given up part way, and the run ends with the frames it wrote
// before it. Anywhere else (a test, the game loop, a benchmark, a worker thread) stop_point()
// does nothing, and costs one load and a branch.
#pragma once

#include <csignal>
#include <stdexcept>

namespace clothlab {

class StepAbandoned : public std::runtime_error {
 public:
  StepAbandoned() : std::runtime_error("a step given up part way: a stop was asked for") {}
};

namespace detail {
inline volatile std::sig_atomic_t g_stop_asked = 0;  // the signal that asked, or 0
inline thread_local int t_stop_points = 0;           // StopPoints alive on this thread
}  // namespace detail

// Asks long work to stop (safe in a signal handler), or takes the question back (0).
inline void ask_to_stop(int signal) noexcept {
  detail::g_stop_asked = signal;
}
inline int stop_asked() noexcept {
  return detail::g_stop_asked;
}

// Throws StepAbandoned if a stop was asked for and a StopPoints lives on this thread.
inline void stop_point() {
  if (detail::g_stop_asked != 0 && detail::t_stop_points > 0) throw StepAbandoned();
}

class StopPoints {
 public:
  StopPoints() { ++detail::t_stop_points; }
  ~StopPoints() { --detail::t_stop_points; }
  StopPoints(const StopPoints&) = delete;
  StopPoints& operator=(const StopPoints&) = delete;
};

}  // namespace clothlab
