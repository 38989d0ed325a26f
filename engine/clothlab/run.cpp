#include "clothlab/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "clothlab/output.hpp"

namespace clothlab {

RunReport run_scene(Scene& scene, const std::filesystem::path& out_dir,
                    const ProgressFn& progress) {
  FrameWriter writer(out_dir);
  RunReport report;
  report.files = writer.files();

  const long total = scene.step_count();
  // A frame every 1/fps seconds: that many steps, rounded, and at least one.
  const long steps_per_frame = std::max(1L, std::lround(1.0 / (scene.output.fps * scene.dt)));

  World& world = scene.world;
  writer.write(world, report.frames++);
  const auto start = std::chrono::steady_clock::now();
  for (long s = 1; s <= total; ++s) {
    world.step(scene.dt);
    if (s % steps_per_frame == 0 || s == total) writer.write(world, report.frames++);
    if (progress) progress(s, total);
  }
  report.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.steps = total;
  return report;
}

}  // namespace clothlab
