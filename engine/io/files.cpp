#include "io/files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include <fmt/format.h>

namespace clothlab {

namespace fs = std::filesystem;

std::string system_reason(int error_number) {
  return std::strerror(error_number);
}

namespace {

// Writes all of `bytes` to `fd`; returns 0, or the errno of the call that failed.
int write_all(int fd, std::string_view bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;  // a signal arrived before anything was written: try again
    } else {
      return n < 0 ? errno : ENOSPC;  // a regular file that takes nothing is full
    }
  }
  return 0;
}

}  // namespace

AppendFile::AppendFile(fs::path path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    throw OutputError(fmt::format("cannot write {}: {}", path_.string(), system_reason(errno)));
  }
}

AppendFile::AppendFile(AppendFile&& other) noexcept
    : path_(std::move(other.path_)),
      fd_(std::exchange(other.fd_, -1)),
      size_(std::exchange(other.size_, 0)) {}

AppendFile& AppendFile::operator=(AppendFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
    size_ = std::exchange(other.size_, 0);
  }
  return *this;
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

void AppendFile::append(std::string_view piece) {
  if (fd_ < 0) throw std::logic_error("AppendFile::append on a file that is not open");
  const int error = write_all(fd_, piece);
  if (error != 0) {
    // Cut off what part of the piece got in, so that the file ends after a whole piece.
    const bool cut = cut_back(size_);
    throw OutputError(fmt::format("writing {} failed: {}{}", path_.string(), system_reason(error),
                                  cut ? "" : " (and the part written could not be cut off)"));
  }
  size_ += static_cast<off_t>(piece.size());
}

bool AppendFile::cut_back(off_t size) noexcept {
  if (fd_ < 0 || size > size_) return false;
  struct stat status {};
  if (::fstat(fd_, &status) == 0 && !S_ISREG(status.st_mode))
    return true;  // a device keeps no bytes
  if (::ftruncate(fd_, size) != 0 || ::lseek(fd_, size, SEEK_SET) != size) return false;
  size_ = size;
  return true;
}

ReplaceFile::ReplaceFile(fs::path path) : path_(std::move(path)) {
  temporary_ =
      path_.parent_path() / fmt::format(".{}.partial-{}", path_.filename().string(), ::getpid());
  fd_ = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    throw OutputError(fmt::format("cannot write {}: {}", path_.string(), system_reason(errno)));
  }
}

ReplaceFile::~ReplaceFile() {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlink(temporary_.c_str());
  }
}

void ReplaceFile::write(std::string_view bytes) {
  if (fd_ < 0) throw std::logic_error("ReplaceFile::write after commit");
  if (const int error = write_all(fd_, bytes); error != 0) {
    throw OutputError(fmt::format("writing {} failed: {}; the file there is as it was",
                                  path_.string(), system_reason(error)));
  }
}

void ReplaceFile::commit(bool sync) {
  if (fd_ < 0) throw std::logic_error("ReplaceFile::commit twice");
  const int fd = std::exchange(fd_, -1);
  int error = 0;
  if (sync && ::fsync(fd) != 0 && errno != EINVAL) error = errno;  // EINVAL: cannot sync (a pipe)
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error == 0 && ::rename(temporary_.c_str(), path_.c_str()) != 0) error = errno;
  if (error != 0) {
    ::unlink(temporary_.c_str());
    throw OutputError(fmt::format("writing {} failed: {}; the file there is as it was",
                                  path_.string(), system_reason(error)));
  }
}

void write_whole_file(const fs::path& path, std::string_view bytes) {
  ReplaceFile file(path);
  file.write(bytes);
  file.commit();
}

void check_writable(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    throw OutputError(fmt::format("cannot write {}: it is a folder", path.string()));
  }
  ReplaceFile probe(path);  // removed again when it goes out of scope
}

}  // namespace clothlab
