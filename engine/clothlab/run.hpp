// run.hpp: runs a scene from start to end, writing its frames.
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include "clothlab/scene.hpp"

namespace clothlab {

struct RunReport {
  long steps = 0;             // steps taken
  long frames = 0;            // frames written
  double wall_seconds = 0.0;  // wall-clock time of the stepping loop [s]
  std::vector<std::filesystem::path> files;
};

// Called after each step with (steps done, steps in all); used for a progress bar.
using ProgressFn = std::function<void(long, long)>;

// Steps `scene` for its whole duration, writing a frame to `out_dir` every 1/fps seconds of
// simulated time (and the first and the last). A SimulationError from the guard propagates
// after the frames before it have been written and flushed.
RunReport run_scene(Scene& scene, const std::filesystem::path& out_dir,
                    const ProgressFn& progress = {});

}  // namespace clothlab
