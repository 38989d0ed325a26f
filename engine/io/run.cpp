#include "io/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "io/mesh_export.hpp"
#include "io/output.hpp"
#include "io/viewer.hpp"

namespace clothlab {

RunReport run_scene(Scene& scene, const RunOutputs& outputs, const ProgressFn& progress) {
  FrameWriter writer(outputs.dir, outputs.velocities || scene.output.velocities,
                     outputs.springs || scene.output.springs);
  MeshExporter meshes(outputs.dir / "frames", outputs.obj, outputs.vtk);
  RunReport report;
  report.files = writer.files();

  const long total = scene.step_count();
  // A frame every 1/fps seconds: that many steps, rounded, and at least one.
  const long steps_per_frame = std::max(1L, std::lround(1.0 / (scene.output.fps * scene.dt)));
  ViewerRecorder viewer(scene.title, scene.source, total / steps_per_frame + 2);

  World& world = scene.world;
  const auto write_frame = [&] {
    writer.write(world, report.frames);
    meshes.write(world, report.frames + 1);  // mesh files count from 1: frame_0001
    if (!outputs.html.empty()) viewer.offer(world);
    ++report.frames;
  };
  // Files that index the frames, and the viewer page, are written however the run ends.
  const auto finish = [&] {
    meshes.finish();
    if (!outputs.html.empty()) viewer.write(world, outputs.html);
  };

  write_frame();
  const auto start = std::chrono::steady_clock::now();
  try {
    for (long s = 1; s <= total; ++s) {
      world.step(scene.dt);
      if (s % steps_per_frame == 0 || s == total) write_frame();
      if (progress) progress(s, total);
    }
  } catch (const SimulationError&) {
    finish();
    throw;
  }
  report.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.steps = total;
  finish();
  if (!outputs.html.empty()) report.files.push_back(outputs.html);
  if (outputs.obj || outputs.vtk) report.files.push_back(outputs.dir / "frames");
  return report;
}

}  // namespace clothlab
