#include "io/npy.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "io/files.hpp"

namespace clothlab {

// The data is written as the machine holds its floats; '<f4' promises little-endian.
static_assert(std::endian::native == std::endian::little, "npy.cpp writes '<f4' as it is");

namespace {

// Writes all `size` bytes at `offset`, again after a partial write or an interrupted call.
// Returns 0, or the errno of the call that failed.
int write_all_at(int fd, const char* data, size_t size, off_t offset) {
  while (size > 0) {
    const ssize_t n = ::pwrite(fd, data, size, offset);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return errno;
    if (n == 0) return EIO;  // no byte taken and no reason given
    data += n;
    size -= static_cast<size_t>(n);
    offset += n;
  }
  return 0;
}

}  // namespace

std::string NpyFrameWriter::header(long frames, Index particles) {
  std::string dict = fmt::format(
      "{{'descr': '<f4', 'fortran_order': False, 'shape': ({}, {}, 3), }}", frames, particles);
  constexpr size_t kPrefix = 10;  // magic (6), version (2), dictionary length (2)
  if (kPrefix + dict.size() + 1 > kHeaderBytes) throw std::logic_error("npy header too long");
  dict.resize(kHeaderBytes - kPrefix - 1, ' ');
  dict += '\n';
  std::string out = "\x93NUMPY";
  out += '\x01';  // version 1.0: a 2-byte header length
  out += '\x00';
  out += static_cast<char>(dict.size() & 0xff);
  out += static_cast<char>(dict.size() >> 8);
  return out + dict;
}

NpyFrameWriter::NpyFrameWriter(const std::filesystem::path& path, Index particles)
    : NpyFrameWriter(Folder::holding(path), path.filename().string(), particles) {}

NpyFrameWriter::NpyFrameWriter(const Folder& folder, const std::string& name, Index particles)
    : path_(folder.path() / name), fd_(open_new_file(folder, name)), particles_(particles) {
  const std::string head = header(0, particles_);
  if (const int error = write_all_at(fd_, head.data(), head.size(), 0)) {
    ::close(fd_);
    fd_ = -1;
    throw std::runtime_error(
        fmt::format("cannot write {}: {}", path_.string(), std::strerror(error)));
  }
}

NpyFrameWriter::~NpyFrameWriter() {
  if (fd_ >= 0) ::close(fd_);
}

NpyFrameWriter::NpyFrameWriter(NpyFrameWriter&& other) noexcept
    : path_(std::move(other.path_)),
      fd_(std::exchange(other.fd_, -1)),
      particles_(other.particles_),
      frames_(other.frames_) {}

NpyFrameWriter& NpyFrameWriter::operator=(NpyFrameWriter&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
    particles_ = other.particles_;
    frames_ = other.frames_;
  }
  return *this;
}

void NpyFrameWriter::append(const Matrix3X& x) {
  if (fd_ < 0) throw std::logic_error(fmt::format("{} is not open", path_.string()));
  if (x.cols() != particles_) {
    throw std::invalid_argument(fmt::format("{} holds frames of {} particles, not {}",
                                            path_.string(), particles_, x.cols()));
  }
  // A column is one particle's x, y, z, and the columns follow each other: (N, 3) in C order.
  const std::vector<float> frame(x.data(), x.data() + x.size());  // doubles rounded to floats
  const size_t bytes = frame.size() * sizeof(float);
  const off_t whole = kHeaderBytes + static_cast<off_t>(frames_) * static_cast<off_t>(bytes);
  const auto fail = [&](int error) {
    // Back to the last whole frame and the header that counts it (best effort: the file is
    // being given up on, and the error that matters is the first).
    const std::string head = header(frames_, particles_);
    write_all_at(fd_, head.data(), head.size(), 0);
    [[maybe_unused]] const int cut = ::ftruncate(fd_, whole);  // a device has nothing to cut
    throw OutputError(fmt::format("cannot write {}: {}", path_.string(), std::strerror(error)));
  };
  // The frame first, then the count that takes it in: never a count without its frame. Each
  // pwrite hands the bytes to the system at once (no buffer here), so a stopped program leaves
  // the file as the last call left it.
  if (const int error =
          write_all_at(fd_, reinterpret_cast<const char*>(frame.data()), bytes, whole)) {
    fail(error);
  }
  const std::string head = header(frames_ + 1, particles_);
  if (const int error = write_all_at(fd_, head.data(), head.size(), 0)) fail(error);
  ++frames_;
}

bool NpyFrameWriter::cut_back(long frames) noexcept {
  if (fd_ < 0 || frames < 0 || frames > frames_) return false;
  const off_t bytes = static_cast<off_t>(particles_) * 3 * static_cast<off_t>(sizeof(float));
  const std::string head = header(frames, particles_);
  if (write_all_at(fd_, head.data(), head.size(), 0) != 0) return false;
  frames_ = frames;
  struct stat status {};
  if (::fstat(fd_, &status) == 0 && !S_ISREG(status.st_mode)) return true;  // a device
  return ::ftruncate(fd_, kHeaderBytes + static_cast<off_t>(frames) * bytes) == 0;
}

}  // namespace clothlab
