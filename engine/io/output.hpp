// output.hpp: what a run writes, frame by frame, into its output folder.
//
//   energy.csv     frame, t [s], kinetic, potential, total [J], px, py, pz [kg m/s]
//   positions.csv  frame, t [s], particle, x, y, z [m]  (a point cloud per frame; ParaView
//                  reads it with "Table To Points", a spreadsheet or pandas reads it as is)
// and, when asked for:
//   positions.npy  in place of positions.csv (`--format npy`, [output] format = "npy"): the
//                  positions as 32-bit floats, shape (frames, N, 3), a fifth of the CSV's size
//                  and read in one call (io/npy.hpp); with velocities, velocities.npy too
//   velocities.csv frame, t [s], particle, vx, vy, vz [m/s]  (the same rows as positions.csv)
//   springs.csv    frame, t [s], effect, spring, i, j, strain, tension [N]  for each spring of
//                  each spring effect ("springs", "bending"): strain = (l - l0) / l0 (empty for
//                  l0 = 0), tension = the spring-damper's pull along the spring, f_sd of lesson
//                  02 (negative: it pushes the ends apart)
//
// Each frame goes to each file in one piece (io/files.hpp), and a frame some file could not take
// is cut off all of them: whenever a run stops, by the guard, a signal, a full disk or a crash,
// every file holds the same whole frames, up to the last good one. No file ever gets an inf or a
// NaN: a frame that would is refused before anything of it is written, and so is a frame with
// a coordinate past 3.4e38, finite as a double but inf as the 32-bit float that a .npy file and
// the viewer page keep.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "clothlab/core/world.hpp"
#include "io/files.hpp"
#include "io/npy.hpp"

namespace clothlab {

class FrameWriter {
 public:
  // Opens the files in `dir`, replacing those of an earlier run; with `velocities` and
  // `springs`, velocities.csv and springs.csv as well; with `npy`, the positions (and
  // velocities) of `particles` particles as .npy files instead of CSV. With `page`, the
  // positions also go to a viewer page as 32-bit floats (write() checks they fit).
  explicit FrameWriter(const Folder& dir, bool velocities = false, bool springs = false,
                       bool npy = false, Index particles = 0, bool page = false);

  // Appends frame number `frame` of the world's current state, after step `step`, to every
  // file. Throws SimulationError, before writing, if a value of the frame is not finite; throws
  // OutputError if a file cannot take it (the frame is then in none of them).
  void write(const World& world, long frame, long step);

  const std::vector<std::filesystem::path>& files() const { return files_; }

 private:
  AppendFile energy_;
  AppendFile positions_;
  AppendFile velocities_;                                         // open only when asked for
  AppendFile springs_;                                            // open only when asked for
  std::optional<NpyFrameWriter> positions_npy_, velocities_npy_;  // in place of the CSV files
  std::vector<std::filesystem::path> files_;
  bool page_ = false;
};

// After a run that was killed (SIGKILL, a crash, a power cut: no chance to cut anything back),
// the files may end on different frames, one of them in a cut line: each frame goes to the other
// files first and to energy.csv last, so energy.csv's whole rows are the frames every file
// holds (after a power cut, which may lose what the system had not yet put on disk, a file may
// hold fewer). Cuts every file in `dir` back to the frames all of them hold whole (and a .npy's
// count with them); returns how many. Only in a run's folder (its marker, io/run_folder.hpp),
// and not while a run writes there. Throws OutputError, and cuts nothing, for a folder that is
// not a run's or a file it cannot read as clothlab writes it (a header that is not clothlab's, a
// row out of frame order, .npy files of different particle counts); throws OutputError naming a
// file it cannot cut. `clothlab repair DIR`.
long cut_to_common_frames(const std::filesystem::path& dir);

}  // namespace clothlab
