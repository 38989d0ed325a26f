// run_cost.hpp: what a run will cost, said before it starts, so that a scene that cannot finish
// in a reasonable time, or whose files will not fit, is known before the wait.
//
// The estimates multiply what the scene asks for (springs, particles, substeps, iterations,
// frames) by costs measured per element: nanoseconds a projection, a sweep of a spring, a byte
// a row. They are upper estimates for the parts that may stop early (strain limiting's sweeps,
// self-collision's passes, conjugate gradients stop when done), and exact counts for the rest.
// [gravitation]'s own warning is the scene reader's (scene/scene_warnings.hpp).
#pragma once

#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace clothlab {

// A part is worth a warning when the run will spend longer than this in it [s].
inline constexpr double kCostWarnAboveSeconds = 600.0;
// The outputs are worth a warning when they will pass this size [bytes].
inline constexpr double kOutputWarnAboveBytes = 2e9;

// The warnings for `scene` run with the given outputs: one line each, empty when nothing is
// costly. `velocities`, `springs` and `npy` as the run's outputs ask (scene or command line).
std::vector<std::string> run_cost_warnings(const Scene& scene, bool velocities, bool springs,
                                           bool npy);

}  // namespace clothlab
