// Frames as a NumPy .npy file: the header the format asks for, a count that follows the frames,
// and a failed write that leaves the whole frames and says why.
#include <doctest/doctest.h>

#include <sys/resource.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "io/npy.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using clothlab::Matrix3X;
using clothlab::NpyFrameWriter;

namespace {

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The dictionary in a header: the text after the 10 bytes of magic, version and length.
std::string dictionary(const std::string& bytes) {
  return bytes.substr(10, NpyFrameWriter::kHeaderBytes - 10);
}

// Frame f of n particles: particle i at (i + f / 3, -i / 7, 0.1 f), values a float cannot hold
// exactly, so that reading back tests the rounding.
Matrix3X frame(int f, int n) {
  Matrix3X x(3, n);
  for (int i = 0; i < n; ++i) {
    x(0, i) = i + f / 3.0;
    x(1, i) = -i / 7.0;
    x(2, i) = 0.1 * f;
  }
  return x;
}

}  // namespace

TEST_CASE("npy: the header is version 1.0 with the data at 128 bytes, a multiple of 64") {
  const fs::path file = test::scratch_path("empty.npy");
  const NpyFrameWriter writer(file, 5);
  const std::string bytes = read_bytes(file);
  REQUIRE(bytes.size() == 128);
  CHECK(bytes.substr(0, 6) == "\x93NUMPY");
  CHECK(bytes[6] == 1);  // major version
  CHECK(bytes[7] == 0);  // minor version
  // The header's length, a little-endian uint16: 128 - 10 = 118 bytes of dictionary.
  CHECK(static_cast<unsigned char>(bytes[8]) == 118);
  CHECK(bytes[9] == 0);
  const std::string dict = dictionary(bytes);
  const std::string expected = "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 5, 3), }";
  CHECK(dict.substr(0, expected.size()) == expected);
  // Padded with spaces and ended by a newline.
  CHECK(dict.find_first_not_of(' ', expected.size()) == dict.size() - 1);
  CHECK(dict.back() == '\n');
  CHECK(writer.frames() == 0);
}

TEST_CASE("npy: each frame appended is counted in the header, its values the doubles rounded") {
  const int n = 4;
  const fs::path file = test::scratch_path("frames.npy");
  NpyFrameWriter writer(file, n);
  const size_t frame_bytes = 3 * n * sizeof(float);  // 12 bytes a particle
  for (int f = 0; f < 3; ++f) {
    writer.append(frame(f, n));
    CAPTURE(f);
    CHECK(writer.frames() == f + 1);
    const std::string bytes = read_bytes(file);
    CHECK(bytes.size() == 128 + (f + 1) * frame_bytes);
    const std::string shape =
        "'shape': (" + std::to_string(f + 1) + ", " + std::to_string(n) + ", 3)";
    CHECK(dictionary(bytes).find(shape) != std::string::npos);
  }
  // Read back as (frames, N, 3) in C order: frame f, particle i, coordinate k at
  // 128 + 4 (3 N f + 3 i + k).
  const std::string bytes = read_bytes(file);
  for (int f = 0; f < 3; ++f) {
    const Matrix3X x = frame(f, n);
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) {
        float value;
        std::memcpy(&value, bytes.data() + 128 + 4 * (3 * n * f + 3 * i + k), sizeof value);
        CHECK(value == static_cast<float>(x(k, i)));
      }
    }
  }
  // A frame of another size is refused, and the file keeps its three.
  CHECK_THROWS_AS(writer.append(frame(3, n + 1)), std::invalid_argument);
  CHECK(read_bytes(file).size() == 128 + 3 * frame_bytes);
}

TEST_CASE("npy: a write that fails names the file and the reason and leaves the whole frames") {
  SUBCASE("a device that is full") {
    if (!fs::exists("/dev/full")) return;
    try {
      NpyFrameWriter writer("/dev/full", 3);
      FAIL("writing to /dev/full did not fail");
    } catch (const std::runtime_error& e) {
      CHECK(std::string(e.what()) == "cannot write /dev/full: " + std::string(strerror(ENOSPC)));
    }
  }
  SUBCASE("a file that reaches the size limit half-way through a frame") {
    // The process may write files of at most the header, one frame and half of another: the
    // second frame's write stops short, then fails with EFBIG. Every check waits until the
    // limit is lifted again, so that the test's own output cannot meet it.
    const int n = 1000;
    const long frame_bytes = 3 * n * sizeof(float);
    const fs::path file = test::scratch_path("limited.npy");
    NpyFrameWriter writer(file, n);
    rlimit before{};
    REQUIRE(getrlimit(RLIMIT_FSIZE, &before) == 0);
    rlimit limited = before;
    limited.rlim_cur = NpyFrameWriter::kHeaderBytes + frame_bytes + frame_bytes / 2;
    void (*const handler)(int) = std::signal(SIGXFSZ, SIG_IGN);  // EFBIG, not a signal
    REQUIRE(setrlimit(RLIMIT_FSIZE, &limited) == 0);
    std::string error;
    bool first_written = false;
    try {
      writer.append(frame(0, n));
      first_written = true;
      writer.append(frame(1, n));
    } catch (const std::runtime_error& e) {
      error = e.what();
    }
    setrlimit(RLIMIT_FSIZE, &before);
    std::signal(SIGXFSZ, handler);
    CHECK(first_written);
    CHECK(error == "cannot write " + file.string() + ": " + std::string(strerror(EFBIG)));
    CHECK(writer.frames() == 1);
    const std::string bytes = read_bytes(file);
    CHECK(bytes.size() == static_cast<size_t>(NpyFrameWriter::kHeaderBytes + frame_bytes));
    CHECK(dictionary(bytes).find("'shape': (1, 1000, 3)") != std::string::npos);
  }
}
