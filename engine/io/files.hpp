// files.hpp: output files that are whole at every moment a user can look at them.
//
// A run can be stopped at any instant: by Ctrl-C, by a full disk, by a crash. Two ways of writing
// keep what is on disk valid whatever the instant:
//   AppendFile   for files that grow frame by frame (the CSV files): each frame goes to the file
//                as one piece, and a piece the system refuses part of is cut off again, so the
//                file ends after the last whole frame;
//   ReplaceFile  for files written in one go (the viewer page, a mesh frame, an index): the text
//                goes to a hidden temporary file beside the target, which is renamed over the
//                target only when complete, so the target is at every moment the old whole
//                file or the new whole file.
// Both throw OutputError, which names the file and the system's reason ("No space left on
// device").
//
// Neither follows a symbolic link, nor writes into a file that another name shares (a hard
// link): a link planted where a run writes, say in a shared folder such as /tmp, would
// otherwise make the run overwrite whatever file it points to. A file is made new under its
// name (an old file or link of that name is removed first, never what a link points to), and
// the files of a run are made relative to its Folder, held open, so that no link put in the
// folder's path while the run goes on can send them elsewhere.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace clothlab {

class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The system's words for an errno value, e.g. "No space left on device".
std::string system_reason(int error_number);

// A folder held open: files made through it go into this folder and nowhere else.
class Folder {
 public:
  // Opens `path` as a folder. With `no_link`, a symbolic link in its place is refused (a run's
  // own folder); without, links on the way are followed (the folder of a page the user named).
  explicit Folder(std::filesystem::path path, bool no_link = false);
  // The folder `name` inside `parent`, made if missing; a symbolic link there is refused.
  Folder(const Folder& parent, const std::string& name);
  Folder(const Folder& other);  // the same folder, on a descriptor of its own
  // The folder that holds `file` (links on the way followed); an error names `file`.
  static Folder holding(const std::filesystem::path& file);
  Folder& operator=(const Folder&) = delete;
  ~Folder();

  int fd() const { return fd_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  Folder() = default;
  std::filesystem::path path_;
  int fd_ = -1;
};

// The folder that holds `path`: its parent, or "." for a bare name.
std::filesystem::path holding_folder(const std::filesystem::path& path);

// Opens `name` in `folder` for writing as a new, empty file: an old regular file or symbolic
// link of that name is removed first (not what the link points to), and the new one is made
// with O_EXCL, which never follows a link. A device (/dev/null) is opened as it is. Returns the
// descriptor; throws OutputError naming the file.
int open_new_file(const Folder& folder, const std::string& name);

class AppendFile {
 public:
  AppendFile() = default;
  // Creates `name` in `folder` as a new file, replacing one of that name (open_new_file).
  AppendFile(const Folder& folder, const std::string& name);
  // The same for `path` in the folder that holds it.
  explicit AppendFile(const std::filesystem::path& path);
  AppendFile(AppendFile&& other) noexcept;
  AppendFile& operator=(AppendFile&& other) noexcept;
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  ~AppendFile();

  // Appends `piece` whole, or not at all: if the system writes only part of it, the file is cut
  // back to where it was and OutputError says why.
  void append(std::string_view piece);

  // Cuts the file back to its first `size` bytes (a size() it had), e.g. to take back a frame
  // another file could not take. Best effort: returns whether it worked.
  bool cut_back(off_t size) noexcept;

  bool is_open() const { return fd_ >= 0; }
  const std::filesystem::path& path() const { return path_; }
  off_t size() const { return size_; }  // bytes of whole pieces [B]

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  off_t size_ = 0;
};

class ReplaceFile {
 public:
  // Opens a temporary file ".NAME.partial-PID" beside `name` in `folder` (open_new_file);
  // throws OutputError if it cannot.
  ReplaceFile(const Folder& folder, const std::string& name);
  // The same for `path` in the folder that holds it.
  explicit ReplaceFile(const std::filesystem::path& path);
  ReplaceFile(const ReplaceFile&) = delete;
  ReplaceFile& operator=(const ReplaceFile&) = delete;
  ~ReplaceFile();  // without commit(): removes the temporary file, leaves `path` as it was

  void write(std::string_view bytes);
  // Puts the file in place of `path`; with `sync`, only once the system has it on disk (so that
  // a power cut cannot leave the name on a file not written: worth it for a big page, not for
  // each small mesh frame).
  void commit(bool sync = false);

 private:
  Folder folder_;
  std::string name_, temporary_;
  int fd_ = -1;
};

// `bytes` as the whole content of `path` (or of `name` in `folder`), through a ReplaceFile.
void write_whole_file(const std::filesystem::path& path, std::string_view bytes);
void write_whole_file(const Folder& folder, const std::string& name, std::string_view bytes);

// Throws OutputError unless a file can be created in the folder that would hold `path` (the
// test file is removed again). Used before a run, so that a bad --html is found before the work.
void check_writable(const std::filesystem::path& path);

}  // namespace clothlab
