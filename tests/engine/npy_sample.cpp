// npy_sample FILE: writes 3 frames of 4 particles to FILE with NpyFrameWriter, for check_npy.py
// to load with NumPy. Frame f puts particle i at (i + f / 3, -i / 7, 0.1 f) [m].
#include <cstdio>
#include <exception>

#include "io/npy.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: npy_sample FILE\n");
    return 2;
  }
  try {
    clothlab::NpyFrameWriter writer(argv[1], 4);
    for (int f = 0; f < 3; ++f) {
      clothlab::Matrix3X x(3, 4);
      for (int i = 0; i < 4; ++i) {
        x(0, i) = i + f / 3.0;
        x(1, i) = -i / 7.0;
        x(2, i) = 0.1 * f;
      }
      writer.append(x);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "npy_sample: %s\n", e.what());
    return 1;
  }
  return 0;
}
