// run_folder.hpp: the folder a run writes into, and what makes it the run's own.
//
// A run writes only into a folder clothlab owns: one it creates, or one holding the marker file
// .clothlab-run that an earlier run left there. So a run
//   - never writes into a folder of the user's by surprise: a folder with other things in it and
//     no marker is refused, unless the user forces it (`clothlab run --force`);
//   - never leaves the last run's frames beside its own: it clears what the last run wrote
//     (the names in kRunOutputNames, and frames/frame_NNNN.obj|vtk) before its first frame, and
//     leaves anything else the user put there alone (a file named `frames`, which no run makes,
//     is refused: the folder of mesh frames has that name);
//   - changes nothing in the folder when it is refused, for the folder or for a page that goes
//     into it;
//   - never shares the folder with another run at the same time: it holds a lock on the marker
//     while it runs (the system lets the lock go when the process ends, however it ends);
//   - never writes through a symbolic link: a run folder, a marker or an output that is a link
//     is not followed (a marker that is not a regular file of one name is refused, an output
//     name that is a link is removed as a name), so that a link planted in a shared folder
//     cannot make a run overwrite or delete a file elsewhere.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string_view>
#include <utility>

#include "io/files.hpp"

namespace clothlab {

// What a run may write in its folder.
inline constexpr std::array<std::string_view, 8> kRunOutputNames = {
    "energy.csv",    "positions.csv",  "velocities.csv", "springs.csv",
    "positions.npy", "velocities.npy", "view.html",      "frames"};

// The marker that says a folder is clothlab's.
inline constexpr std::string_view kRunFolderMarker = ".clothlab-run";

class RunFolder {
 public:
  // Takes `dir` for a run: creates it, or checks it is clothlab's (or empty, or `force`), locks
  // it, and clears the last run's outputs. Throws OutputError saying what is wrong and what to do,
  // and then has changed nothing in the folder: a `frames` that is not a folder (a user's file
  // of that name, which clearing would lose) is refused, even with `force`, and so is `page`,
  // the viewer page when it goes into this folder, as check_page_target refuses it.
  RunFolder(std::filesystem::path dir, bool force, const std::filesystem::path& page = {});
  ~RunFolder();  // lets the lock go; the marker stays
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;

  const std::filesystem::path& dir() const { return dir_; }
  // The folder, held open: the run's files are made through it (io/files.hpp).
  const Folder& folder() const { return *folder_; }

 private:
  std::filesystem::path dir_;
  std::optional<Folder> folder_;
  int lock_fd_ = -1;
};

// Whether `dir` is a folder that holds only names a run writes (kRunOutputNames).
bool holds_only_run_outputs(const std::filesystem::path& dir);

// The lock of a run folder that a page is written into from outside it (--html): held while
// the page may be written, so that no run starts there meanwhile.
class PageFolderLock {
 public:
  PageFolderLock() = default;
  explicit PageFolderLock(int fd) : fd_(fd) {}
  PageFolderLock(PageFolderLock&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  PageFolderLock& operator=(PageFolderLock&&) = delete;
  ~PageFolderLock();

 private:
  int fd_ = -1;
};

// Takes the run folder held open as `folder` for work on its files other than a run's
// (`clothlab repair`): refuses a folder with no clothlab marker, as a run does without --force,
// and one that a run writes into now, and returns the folder's lock, which keeps a run out
// meanwhile. Throws OutputError saying what is wrong.
PageFolderLock lock_run_folder(const Folder& folder);

// Throws OutputError if `page` is an existing file that is not a clothlab viewer page (one that
// starts as the template does), or a symbolic link, unless `force` (so --html cannot overwrite
// a user's file by surprise); if no file can be written where it goes; or if it goes into
// another run's folder while that run writes there. Returns the lock of that folder, when the
// page goes into one and `lock_folder` (false for the run's own folder, which RunFolder locks).
PageFolderLock check_page_target(const std::filesystem::path& page, bool force,
                                 bool lock_folder = true);

}  // namespace clothlab
