// output.hpp: what a run writes, frame by frame, into its output folder.
//
//   energy.csv     frame, t [s], kinetic, potential, total [J], px, py, pz [kg m/s]
//   positions.csv  frame, t [s], particle, x, y, z [m]  (a point cloud per frame; ParaView
//                  reads it with "Table To Points", a spreadsheet or pandas reads it as is)
// and, when asked for:
//   velocities.csv frame, t [s], particle, vx, vy, vz [m/s]  (the same rows as positions.csv)
//   springs.csv    frame, t [s], effect, spring, i, j, strain, tension [N]  for each spring of
//                  each spring effect ("springs", "bending"): strain = (l - l0) / l0 (empty for
//                  l0 = 0), tension = the spring-damper's pull along the spring, f_sd of lesson
//                  02 (negative: it pushes the ends apart)
//
// Every row is flushed as soon as its frame is written, so a run stopped by the guard leaves
// complete, valid files up to the last good frame.
#pragma once

#include <filesystem>
#include <fstream>
#include <vector>

#include "clothlab/core/world.hpp"

namespace clothlab {

// Opens `path` for writing, replacing what was there; throws if it cannot.
std::ofstream open_for_writing(const std::filesystem::path& path);

class FrameWriter {
 public:
  // Creates `dir` if needed and opens the files, replacing those of an earlier run; with
  // `velocities` and `springs`, velocities.csv and springs.csv as well.
  explicit FrameWriter(const std::filesystem::path& dir, bool velocities = false,
                       bool springs = false);

  // Appends frame number `frame` of the world's current state to every file.
  void write(const World& world, long frame);

  const std::vector<std::filesystem::path>& files() const { return files_; }

 private:
  std::ofstream energy_;
  std::ofstream positions_;
  std::ofstream velocities_;  // open only when asked for
  std::ofstream springs_;     // open only when asked for
  std::vector<std::filesystem::path> files_;
};

}  // namespace clothlab
