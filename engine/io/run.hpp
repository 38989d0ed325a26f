// run.hpp: runs a scene from start to end, writing its frames.
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include "scene/scene.hpp"

namespace clothlab {

// Where a run writes, and what.
struct RunOutputs {
  std::filesystem::path dir;   // energy.csv and positions.csv go here
  std::filesystem::path html;  // the viewer page (empty: no page)
  bool obj = false;            // an OBJ sequence in dir/frames/
  bool vtk = false;            // a VTK series in dir/frames/
  bool velocities = false;     // velocities.csv, even if the scene's [output] does not ask
  bool springs = false;        // springs.csv, even if the scene's [output] does not ask

  // The usual outputs: the CSV files and dir/view.html.
  static RunOutputs in(const std::filesystem::path& dir) { return {dir, dir / "view.html"}; }
};

struct RunReport {
  long steps = 0;             // steps taken
  long frames = 0;            // frames written
  double wall_seconds = 0.0;  // wall-clock time of the stepping loop [s]
  std::vector<std::filesystem::path> files;
};

// Called after each step with (steps done, steps in all); used for a progress bar.
using ProgressFn = std::function<void(long, long)>;

// Steps `scene` for its whole duration, writing a frame every 1/fps seconds of simulated time
// (and the first and the last). A SimulationError from the guard propagates after the frames
// before it have been written and flushed, and the viewer page shows them.
RunReport run_scene(Scene& scene, const RunOutputs& outputs, const ProgressFn& progress = {});

// The same with the usual outputs in `out_dir`.
inline RunReport run_scene(Scene& scene, const std::filesystem::path& out_dir,
                           const ProgressFn& progress = {}) {
  return run_scene(scene, RunOutputs::in(out_dir), progress);
}

}  // namespace clothlab
