#!/usr/bin/env python3
"""Loads a file NpyFrameWriter wrote (tests/engine/npy_sample.cpp) with NumPy and checks it.

  1. numpy.load reads it: dtype float32, shape (3 frames, 4 particles, 3), the values the doubles
     of npy_sample.cpp rounded to float32, particle i of frame f at [f, i].
  2. Half a frame more at the end, as a run stopped between writing a frame and counting it
     leaves, is not read: the header's shape says how much data there is.

Exit 0 when both hold, 1 when one fails, 77 (ctest's "skipped") when Python has no NumPy.
"""
import os
import subprocess
import sys

try:
    import numpy
except ImportError:
    print("no numpy for this python: the .npy file is not loaded")
    sys.exit(77)


def expected():
    x = numpy.empty((3, 4, 3), dtype=numpy.float32)
    for f in range(3):
        for i in range(4):
            x[f, i] = (i + f / 3.0, -i / 7.0, 0.1 * f)  # doubles, rounded as they are stored
    return x


def main():
    writer, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, "positions.npy")
    subprocess.run([writer, path], check=True)
    ok = True
    for mmap_mode in (None, "r"):
        x = numpy.load(path, mmap_mode=mmap_mode)
        if x.dtype != numpy.float32 or x.shape != (3, 4, 3) or not numpy.array_equal(x, expected()):
            print(f"FAIL: numpy.load(mmap_mode={mmap_mode}) read {x.dtype} {x.shape}:\n{x}")
            ok = False
    with open(path, "ab") as f:
        f.write(b"\x00" * (4 * 3 * 4 // 2))
    x = numpy.load(path)
    if x.shape != (3, 4, 3) or not numpy.array_equal(x, expected()):
        print(f"FAIL: with half a frame more at the end, numpy.load read {x.shape}")
        ok = False
    print("numpy reads the frames" if ok else "")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
