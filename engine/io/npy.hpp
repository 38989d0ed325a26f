// npy.hpp: frames of positions as one NumPy .npy file: compact, and loadable at every moment.
//
//   positions.npy  dtype '<f4' (little-endian 32-bit floats), shape (frames, N, 3), C order:
//                  numpy.load("positions.npy")[f, i] is particle i's (x, y, z) [m] in frame f.
//
// 12 bytes per particle per frame, against about 60 in positions.csv, and read in one call.
// 32-bit floats keep about 7 significant digits: a 1 m cloth to within 0.1 um, plenty to plot
// or to look at; positions.csv keeps every bit of the doubles.
//
// The file is valid after every frame. The header is written once with room for a 20-digit
// frame count, so it never grows; each append writes the frame's bytes after the last whole
// frame, then rewrites the count in the header. A run stopped between the two leaves a header
// that names only the whole frames (a reader reads the shape's worth of data and no more). A
// failed write is cut back to the last whole frame and throws, naming the file and the reason.
#pragma once

#include <filesystem>
#include <string>

#include "clothlab/core/types.hpp"
#include "io/files.hpp"

namespace clothlab {

class NpyFrameWriter {
 public:
  // Creates `name` in `folder` as a new file of no frames of `particles` particles, replacing
  // what was there under that name (open_new_file in io/files.hpp: never through a link).
  NpyFrameWriter(const Folder& folder, const std::string& name, Index particles);
  // The same for `path` in the folder that holds it.
  NpyFrameWriter(const std::filesystem::path& path, Index particles);
  ~NpyFrameWriter();
  NpyFrameWriter(NpyFrameWriter&& other) noexcept;
  NpyFrameWriter& operator=(NpyFrameWriter&& other) noexcept;
  NpyFrameWriter(const NpyFrameWriter&) = delete;
  NpyFrameWriter& operator=(const NpyFrameWriter&) = delete;

  // Appends `x` (3 x N, one particle per column, N as constructed) as the next frame.
  void append(const Matrix3X& x);

  // Cuts the file back to its first `frames` frames (no more than it has), e.g. to take back a
  // frame another file could not take. Best effort: returns whether it worked.
  bool cut_back(long frames) noexcept;

  long frames() const { return frames_; }
  const std::filesystem::path& path() const { return path_; }

  // The header of a file of `frames` frames of `particles` particles: the magic "\x93NUMPY",
  // version 1.0, the dictionary's length (2 bytes, little-endian) and the dictionary, padded
  // with spaces and ended by '\n' to kHeaderBytes in all.
  static std::string header(long frames, Index particles);
  static constexpr long kHeaderBytes = 128;  // where the data starts: a multiple of 64 [bytes]

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  Index particles_ = 0;
  long frames_ = 0;  // whole frames in the file, as its header says
};

}  // namespace clothlab
