#include "io/run_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/files.hpp"

namespace clothlab {

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

// Removes what an earlier run wrote in `dir`: the output files, the mesh frames, and the
// temporary files of a write that was stopped. Anything else stays.
void clear_last_run(const fs::path& dir) {
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name == "frames" && entry.is_directory()) {
      for (const fs::directory_entry& frame : fs::directory_iterator(entry.path())) {
        if (is_mesh_frame_name(frame.path().filename().string())) fs::remove(frame.path());
      }
      std::error_code ignored;
      fs::remove(entry.path(), ignored);  // only if now empty: a user's file in it stays
    } else if ((is_output_name(name) || is_partial_file(name)) && !entry.is_directory()) {
      fs::remove(entry.path());
    }
  }
}

}  // namespace

RunFolder::RunFolder(fs::path dir, bool force) : dir_(std::move(dir)) {
  const std::string shown = dir_.string();
  std::error_code ec;
  const fs::file_status status = fs::status(dir_, ec);
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
  const fs::path marker = dir_ / kRunFolderMarker;
  if (!fs::exists(marker) && !force) {
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

  lock_fd_ = ::open(marker.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (lock_fd_ < 0) {
    throw OutputError(fmt::format("cannot write into {}: {}", shown, system_reason(errno)));
  }
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(lock_fd_);
    lock_fd_ = -1;
    if (error != EWOULDBLOCK) {
      throw OutputError(fmt::format("cannot lock {}: {}", marker.string(), system_reason(error)));
    }
    std::ifstream in(marker);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t at = text.find("process ");
    const std::string who =
        at == std::string::npos
            ? "another clothlab run"
            : "another clothlab run (" + text.substr(at, text.find('\n', at) - at) + ")";
    throw OutputError(
        fmt::format("{} is writing into {} now; wait for it to end, or choose "
                    "another --out",
                    who, shown));
  }
  // The folder is ours until the process ends: say so in the marker, and clear the last run.
  const std::string text = fmt::format(
      "This folder holds the output of a clothlab run. The next run into it replaces its "
      "energy.csv,\n"
      "positions.csv, velocities.csv, springs.csv, positions.npy, velocities.npy, view.html and\n"
      "frames/frame_NNNN.* files, and leaves any other file alone.\n"
      "last run: process {}\n",
      ::getpid());
  if (::ftruncate(lock_fd_, 0) != 0 || ::write(lock_fd_, text.data(), text.size()) < 0) {
    throw OutputError(fmt::format("cannot write {}: {}", marker.string(), system_reason(errno)));
  }
  clear_last_run(dir_);
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

void check_page_target(const fs::path& page, bool force) {
  std::error_code ec;
  if (fs::is_regular_file(page, ec) && !force) {
    // Every page starts with the template's opening comment, which names it.
    std::ifstream in(page, std::ios::binary);
    std::string head(1024, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<size_t>(in.gcount()));
    if (head.find("clothlab viewer") == std::string::npos) {
      throw OutputError(
          fmt::format("{} exists and is not a clothlab viewer page; choose another "
                      "--html, or add --force to replace it",
                      page.string()));
    }
  } else if (fs::exists(page, ec) && !fs::is_regular_file(page, ec)) {
    throw OutputError(fmt::format("cannot write {}: it is {}", page.string(),
                                  fs::is_directory(page, ec) ? "a folder" : "not a regular file"));
  }
  check_writable(page);
}

}  // namespace clothlab
