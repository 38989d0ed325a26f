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

class AppendFile {
 public:
  AppendFile() = default;
  // Creates `path`, or empties it if it exists.
  explicit AppendFile(std::filesystem::path path);
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
  // Opens a temporary file ".NAME.partial-PID" beside `path`; throws OutputError if it cannot.
  explicit ReplaceFile(std::filesystem::path path);
  ReplaceFile(const ReplaceFile&) = delete;
  ReplaceFile& operator=(const ReplaceFile&) = delete;
  ~ReplaceFile();  // without commit(): removes the temporary file, leaves `path` as it was

  void write(std::string_view bytes);
  // Puts the file in place of `path`; with `sync`, only once the system has it on disk (so that
  // a power cut cannot leave the name on a file not written: worth it for a big page, not for
  // each small mesh frame).
  void commit(bool sync = false);

 private:
  std::filesystem::path path_, temporary_;
  int fd_ = -1;
};

// `bytes` as the whole content of `path`, through a ReplaceFile.
void write_whole_file(const std::filesystem::path& path, std::string_view bytes);

// Throws OutputError unless a file can be created in the folder that would hold `path` (the
// test file is removed again). Used before a run, so that a bad --html is found before the work.
void check_writable(const std::filesystem::path& path);

}  // namespace clothlab
