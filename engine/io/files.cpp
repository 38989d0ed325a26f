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

// "cannot write PATH: REASON", where a link refused by O_NOFOLLOW (ELOOP) says so.
OutputError cannot_write(const fs::path& path, int error) {
  return OutputError(fmt::format("cannot write {}: {}", path.string(),
                                 error == ELOOP ? "it is a symbolic link, which clothlab does not "
                                                  "follow; remove it, or choose another place"
                                                : system_reason(error)));
}

}  // namespace

fs::path holding_folder(const fs::path& path) {
  return path.has_parent_path() ? path.parent_path() : fs::path(".");
}

Folder Folder::holding(const fs::path& file) {
  Folder folder;
  folder.path_ = holding_folder(file);
  folder.fd_ = ::open(folder.path_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (folder.fd_ < 0) throw cannot_write(file, errno);  // the file the user named
  return folder;
}

Folder::Folder(fs::path path, bool no_link) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC | (no_link ? O_NOFOLLOW : 0));
  if (fd_ < 0) throw cannot_write(path_, errno);
}

Folder::Folder(const Folder& parent, const std::string& name) : path_(parent.path() / name) {
  if (::mkdirat(parent.fd(), name.c_str(), 0777) != 0 && errno != EEXIST) {
    throw cannot_write(path_, errno);
  }
  fd_ = ::openat(parent.fd(), name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd_ < 0) throw cannot_write(path_, errno);
}

Folder::Folder(const Folder& other) : path_(other.path_) {
  fd_ = ::fcntl(other.fd_, F_DUPFD_CLOEXEC, 0);
  if (fd_ < 0) throw cannot_write(path_, errno);
}

Folder::~Folder() {
  if (fd_ >= 0) ::close(fd_);
}

int open_new_file(const Folder& folder, const std::string& name) {
  const int dir = folder.fd();
  struct stat status {};
  int flags = O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC;
  if (::fstatat(dir, name.c_str(), &status, AT_SYMLINK_NOFOLLOW) == 0) {
    if (S_ISREG(status.st_mode) || S_ISLNK(status.st_mode)) {
      // The name is taken by an old file or a link: the name goes, the file a link names stays.
      if (::unlinkat(dir, name.c_str(), 0) != 0) throw cannot_write(folder.path() / name, errno);
    } else if (!S_ISDIR(status.st_mode)) {
      flags = O_WRONLY | O_NOFOLLOW | O_CLOEXEC;  // a device or a pipe: written as it is
    }
  }
  const int fd = ::openat(dir, name.c_str(), flags, 0666);
  if (fd < 0) throw cannot_write(folder.path() / name, errno);
  return fd;
}

AppendFile::AppendFile(const Folder& folder, const std::string& name)
    : path_(folder.path() / name), fd_(open_new_file(folder, name)) {}

AppendFile::AppendFile(const fs::path& path)
    : AppendFile(Folder::holding(path), path.filename().string()) {}

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

ReplaceFile::ReplaceFile(const Folder& folder, const std::string& name)
    : folder_(folder), name_(name), temporary_(fmt::format(".{}.partial-{}", name, ::getpid())) {
  fd_ = open_new_file(folder_, temporary_);
}

ReplaceFile::ReplaceFile(const fs::path& path)
    : ReplaceFile(Folder::holding(path), path.filename().string()) {}

ReplaceFile::~ReplaceFile() {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlinkat(folder_.fd(), temporary_.c_str(), 0);
  }
}

void ReplaceFile::write(std::string_view bytes) {
  if (fd_ < 0) throw std::logic_error("ReplaceFile::write after commit");
  if (const int error = write_all(fd_, bytes); error != 0) {
    throw OutputError(fmt::format("writing {} failed: {}; the file there is as it was",
                                  (folder_.path() / name_).string(), system_reason(error)));
  }
}

void ReplaceFile::commit(bool sync) {
  if (fd_ < 0) throw std::logic_error("ReplaceFile::commit twice");
  const int fd = std::exchange(fd_, -1);
  int error = 0;
  if (sync && ::fsync(fd) != 0 && errno != EINVAL) error = errno;  // EINVAL: cannot sync (a pipe)
  if (::close(fd) != 0 && error == 0) error = errno;
  // renameat replaces the name: a link there goes, the file it points to is not touched.
  if (error == 0 &&
      ::renameat(folder_.fd(), temporary_.c_str(), folder_.fd(), name_.c_str()) != 0) {
    error = errno;
  }
  if (error != 0) {
    ::unlinkat(folder_.fd(), temporary_.c_str(), 0);
    throw OutputError(fmt::format("writing {} failed: {}; the file there is as it was",
                                  (folder_.path() / name_).string(), system_reason(error)));
  }
}

void write_whole_file(const Folder& folder, const std::string& name, std::string_view bytes) {
  ReplaceFile file(folder, name);
  file.write(bytes);
  file.commit();
}

void write_whole_file(const fs::path& path, std::string_view bytes) {
  write_whole_file(Folder::holding(path), path.filename().string(), bytes);
}

void check_writable(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    throw OutputError(fmt::format("cannot write {}: it is a folder", path.string()));
  }
  ReplaceFile probe(path);  // removed again when it goes out of scope
}

}  // namespace clothlab
