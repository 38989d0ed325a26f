#include "io/run_folder.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/files.hpp"

namespace clothlab {

extern const std::string_view kViewerTemplate;  // viewer.html, embedded at build time

namespace fs = std::filesystem;

namespace {

bool is_output_name(const std::string& name) {
  return std::find(kRunOutputNames.begin(), kRunOutputNames.end(), name) != kRunOutputNames.end();
}

// A temporary file a stopped write left behind: ".NAME.partial-PID" (io/files.hpp).
bool is_partial_file(const std::string& name) {
  return name.size() > 1 && name[0] == '.' && name.find(".partial-") != std::string::npos;
}

// What a mesh export writes in frames/: frame_0001.obj, frame_0001.vtk, frames.vtk.series.
bool is_mesh_frame_name(const std::string& name) {
  if (name == "frames.vtk.series" || is_partial_file(name)) return true;
  const fs::path path(name);
  const std::string stem = path.stem().string();
  const std::string ext = path.extension().string();
  return (ext == ".obj" || ext == ".vtk") && stem.size() > 6 && stem.rfind("frame_", 0) == 0 &&
         std::all_of(stem.begin() + 6, stem.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// "a", "a and b", "a, b and c", "a, b, c and 2 more".
std::string some_entries(const std::vector<std::string>& names) {
  const size_t shown = std::min<size_t>(names.size(), 3);
  std::string list;
  for (size_t k = 0; k < shown; ++k) {
    const bool last = k + 1 == shown && names.size() == shown;
    list += (k == 0 ? "" : last ? " and " : ", ") + names[k];
  }
  if (names.size() > shown) list += fmt::format(" and {} more", names.size() - shown);
  return list;
}

std::vector<std::string> entry_names(const fs::path& dir) {
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    std::string name = entry.path().filename().string();
    if (entry.is_directory()) name += "/";
    names.push_back(std::move(name));
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The names in the folder held open as `dir` (fdopendir on a descriptor of its own).
std::vector<std::string> names_in(const Folder& dir) {
  std::vector<std::string> names;
  const int fd = ::fcntl(dir.fd(), F_DUPFD_CLOEXEC, 0);
  DIR* const listing = fd >= 0 ? ::fdopendir(fd) : nullptr;
  if (!listing) {
    if (fd >= 0) ::close(fd);
    throw OutputError(fmt::format("cannot read {}: {}", dir.path().string(), system_reason(errno)));
  }
  ::rewinddir(listing);
  while (const dirent* entry = ::readdir(listing)) {
    const std::string name = entry->d_name;
    if (name != "." && name != "..") names.push_back(name);
  }
  ::closedir(listing);
  return names;
}

// Removes what an earlier run wrote in `dir`: the output files, the mesh frames, and the
// temporary files of a write that was stopped. Anything else stays. Nothing here follows a
// symbolic link: a link of an output's name is removed as the name it is (unlinkat), and a
// `frames` that is a link to a folder goes as a link, its target's files untouched.
void clear_last_run(const Folder& dir) {
  const auto remove = [](const Folder& folder, const std::string& name) {
    if (::unlinkat(folder.fd(), name.c_str(), 0) != 0 && errno != ENOENT) {
      throw OutputError(fmt::format("cannot remove {} of the last run: {}",
                                    (folder.path() / name).string(), system_reason(errno)));
    }
  };
  for (const std::string& name : names_in(dir)) {
    struct stat status {};
    if (::fstatat(dir.fd(), name.c_str(), &status, AT_SYMLINK_NOFOLLOW) != 0) continue;
    if (name == "frames" && S_ISDIR(status.st_mode)) {
      const Folder frames(dir, name);  // opened without following a link put there meanwhile
      for (const std::string& frame : names_in(frames)) {
        struct stat frame_status {};
        if (is_mesh_frame_name(frame) &&
            ::fstatat(frames.fd(), frame.c_str(), &frame_status, AT_SYMLINK_NOFOLLOW) == 0 &&
            !S_ISDIR(frame_status.st_mode)) {
          remove(frames, frame);
        }
      }
      ::unlinkat(dir.fd(), name.c_str(), AT_REMOVEDIR);  // only if now empty: a user's file stays
    } else if (name == "frames" && !S_ISLNK(status.st_mode)) {
      continue;  // no run makes a file of that name: a user's, which RunFolder refuses to clear
    } else if ((is_output_name(name) || is_partial_file(name)) && !S_ISDIR(status.st_mode)) {
      remove(dir, name);
    }
  }
}

// What the marker at `marker` is, without following a link: "" for clothlab's marker (a
// regular file of one name), otherwise why it is not.
std::string not_a_marker(const struct stat& status) {
  if (S_ISLNK(status.st_mode)) return "a symbolic link";
  if (!S_ISREG(status.st_mode)) return "not a regular file";
  if (status.st_nlink != 1) return "a file with other names (hard links)";
  return "";
}

[[noreturn]] void refuse_marker(const fs::path& marker, const std::string& why) {
  throw OutputError(fmt::format(
      "{} is {}, not clothlab's marker, and a run writes into that file; remove it, or choose "
      "another --out",
      marker.string(), why));
}

// Takes the lock on the marker `marker_fd` of the folder `shown`, or throws saying who holds it.
void lock_marker(int marker_fd, const fs::path& marker, const std::string& shown,
                 std::string_view what) {
  if (::flock(marker_fd, LOCK_EX | LOCK_NB) == 0) return;
  const int error = errno;
  if (error != EWOULDBLOCK) {
    throw OutputError(fmt::format("cannot lock {}: {}", marker.string(), system_reason(error)));
  }
  std::string text(512, '\0');
  const ssize_t got = ::pread(marker_fd, text.data(), text.size(), 0);
  text.resize(got > 0 ? static_cast<size_t>(got) : 0);
  const size_t at = text.find("process ");
  const std::string who =
      at == std::string::npos
          ? "another clothlab run"
          : "another clothlab run (" + text.substr(at, text.find('\n', at) - at) + ")";
  throw OutputError(fmt::format(
      "{} is writing into {} now; wait for it to end, or choose another {}", who, shown, what));
}

// Opens the marker of `folder` without following a link, and checks it is clothlab's; -1 when
// there is none and `create` is false.
int open_marker(const Folder& folder, bool create) {
  const fs::path marker = folder.path() / kRunFolderMarker;
  const std::string name(kRunFolderMarker);
  struct stat status {};
  if (::fstatat(folder.fd(), name.c_str(), &status, AT_SYMLINK_NOFOLLOW) == 0) {
    if (const std::string why = not_a_marker(status); !why.empty()) refuse_marker(marker, why);
  } else if (!create) {
    return -1;
  }
  const int fd = ::openat(folder.fd(), name.c_str(),
                          (create ? O_RDWR | O_CREAT : O_RDONLY) | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) {
    if (errno == ELOOP) refuse_marker(marker, "a symbolic link");
    if (!create && errno == ENOENT) return -1;
    throw OutputError(
        fmt::format("cannot write into {}: {}", folder.path().string(), system_reason(errno)));
  }
  // Checked again on what was opened: a link or a second name put there meanwhile.
  if (::fstat(fd, &status) != 0 || !not_a_marker(status).empty()) {
    ::close(fd);
    refuse_marker(marker, "not a regular file of one name");
  }
  return fd;
}

// Throws OutputError if `frames` in `folder` is something a run neither makes nor may remove: a
// run makes a folder there (or a link of that name is removed as a link), so a file of that name
// is the user's, and clearing the last run's frames would delete it.
void check_frames_name(const Folder& folder) {
  struct stat status {};
  if (::fstatat(folder.fd(), "frames", &status, AT_SYMLINK_NOFOLLOW) != 0) return;
  if (S_ISDIR(status.st_mode) || S_ISLNK(status.st_mode)) return;
  throw OutputError(fmt::format(
      "{} is a file, not the folder of mesh frames (frames/frame_NNNN.obj) that a run keeps "
      "there, and a run into {} would remove it; move or rename it, or choose another --out",
      (folder.path() / "frames").string(), folder.path().string()));
}

}  // namespace

RunFolder::RunFolder(fs::path dir, bool force, const fs::path& page) : dir_(std::move(dir)) {
  const std::string shown = dir_.string();
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(dir_, ec);
  if (fs::is_symlink(status)) {
    throw OutputError(
        fmt::format("cannot write into {}: it is a symbolic link, which a run does not follow; "
                    "give the folder it points to as --out",
                    shown));
  }
  if (fs::exists(status) && !fs::is_directory(status)) {
    throw OutputError(
        fmt::format("cannot write into {}: it is a file, not a folder; choose "
                    "another --out",
                    shown));
  }
  if (!fs::exists(status)) {
    fs::create_directories(dir_, ec);
    if (ec) throw OutputError(fmt::format("cannot create {}: {}", shown, ec.message()));
  }
  folder_.emplace(dir_, /*no_link=*/true);
  const fs::path marker = dir_ / kRunFolderMarker;
  if (const int existing = open_marker(*folder_, false); existing >= 0) {
    ::close(existing);
  } else if (!force) {
    const std::vector<std::string> names = entry_names(dir_);
    if (!names.empty()) {
      throw OutputError(fmt::format(
          "{} is not a clothlab output folder: it holds {} and no {} marker, and a run would "
          "replace files there; choose another --out (a new or empty folder), or add --force to "
          "write into it anyway (files named as clothlab's outputs are replaced, others are left "
          "alone)",
          shown, some_entries(names), kRunFolderMarker));
    }
  }
  // What would refuse the run is found before the marker is made or rewritten and anything is
  // cleared: a refused run leaves the folder as it was. A file or link under a name the run
  // clears (view.html) is the last run's page, and goes with it.
  check_frames_name(*folder_);
  const std::string page_name = page.filename().string();
  struct stat page_status {};
  const bool cleared =
      (is_output_name(page_name) || is_partial_file(page_name)) &&
      ::fstatat(folder_->fd(), page_name.c_str(), &page_status, AT_SYMLINK_NOFOLLOW) == 0 &&
      (S_ISREG(page_status.st_mode) || S_ISLNK(page_status.st_mode));
  if (!page.empty() && !cleared) check_page_target(page, force, /*lock_folder=*/false);

  lock_fd_ = open_marker(*folder_, true);
  try {
    lock_marker(lock_fd_, marker, shown, "--out");
  } catch (...) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw;
  }
  // The folder is ours until the process ends: say so in the marker, and clear the last run.
  const std::string text = fmt::format(
      "This folder holds the output of a clothlab run. The next run into it replaces its "
      "energy.csv,\n"
      "positions.csv, velocities.csv, springs.csv, positions.npy, velocities.npy, view.html and\n"
      "frames/frame_NNNN.* files, and leaves any other file alone.\n"
      "last run: process {}\n",
      ::getpid());
  if (::ftruncate(lock_fd_, 0) != 0 || ::pwrite(lock_fd_, text.data(), text.size(), 0) < 0) {
    throw OutputError(fmt::format("cannot write {}: {}", marker.string(), system_reason(errno)));
  }
  clear_last_run(*folder_);
}

RunFolder::~RunFolder() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // closing lets the lock go
}

bool holds_only_run_outputs(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return false;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
    if (!is_output_name(entry.path().filename().string())) return false;
  }
  return !ec;
}

PageFolderLock::~PageFolderLock() {
  if (fd_ >= 0) ::close(fd_);
}

PageFolderLock lock_run_folder(const Folder& folder) {
  const int marker = open_marker(folder, false);
  if (marker < 0) {
    throw OutputError(fmt::format(
        "{} is not a clothlab output folder: it holds no {} marker, and repair cuts the files "
        "there; nothing was cut",
        folder.path().string(), kRunFolderMarker));
  }
  PageFolderLock lock(marker);
  lock_marker(marker, folder.path() / kRunFolderMarker, folder.path().string(), "folder");
  return lock;
}

PageFolderLock check_page_target(const fs::path& page, bool force, bool lock_folder) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(page, ec);
  if (fs::is_symlink(status) && !force) {
    throw OutputError(
        fmt::format("{} is a symbolic link; choose another --html, or add --force to replace the "
                    "link (the file it points to is left alone)",
                    page.string()));
  }
  if (fs::is_regular_file(status) && !force) {
    // Every page starts as the template does, with the comment that names it; a user's note
    // that merely mentions the viewer does not.
    const std::string_view name = "clothlab viewer:";
    const std::string_view opening =
        kViewerTemplate.substr(0, kViewerTemplate.find(name) + name.size());
    std::string head(opening.size(), '\0');
    const int fd = ::open(page.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    const ssize_t got = fd >= 0 ? ::read(fd, head.data(), head.size()) : -1;
    if (fd >= 0) ::close(fd);
    if (got != static_cast<ssize_t>(head.size()) || head != opening) {
      throw OutputError(
          fmt::format("{} exists and is not a clothlab viewer page; choose another "
                      "--html, or add --force to replace it",
                      page.string()));
    }
  } else if (fs::exists(status) && !fs::is_regular_file(status) && !fs::is_symlink(status)) {
    throw OutputError(fmt::format("cannot write {}: it is {}", page.string(),
                                  fs::is_directory(status) ? "a folder" : "not a regular file"));
  }
  check_writable(page);
  // A page in another run's folder: not while that run writes there, nor a run starts there
  // while this one writes the page.
  if (!lock_folder) return {};
  const std::string folder = holding_folder(page).string();
  const int marker = open_marker(Folder::holding(page), false);
  if (marker < 0) return {};
  PageFolderLock lock(marker);
  lock_marker(marker, holding_folder(page) / kRunFolderMarker, folder, "--html");
  return lock;
}

}  // namespace clothlab
