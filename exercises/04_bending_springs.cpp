// Lesson 04, bending springs: the exercise kernels.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`.
// Compare a sheet with and without bending on your code with
//   ./build/clothlab-student run lessons/04-bending-springs/drape-stiff.toml
// Every symbol is explained in lessons/04-bending-springs/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/not_implemented.hpp"

namespace clothlab {

// Exercise ex04.1: the bending pairs of a rows x cols grid, as grid-local indices r * cols + c:
// (r,c)-(r,c+2) along every row and (r,c)-(r+2,c) down every column.
// Hints:
//   1. Look at structural_pairs() in engine/clothlab/bodies/cloth.cpp: the same loops, two apart.
//   2. How many? rows * (cols - 2) along the rows plus cols * (rows - 2) down the columns, and
//      none along a side with fewer than 3 particles.
//   3. Each pair once: (a, b) and (b, a) would be two springs on the same two particles.
std::vector<IndexPair> bending_pairs(Index rows, Index cols) {
  // BEGIN ex04.1: see lessons/04-bending-springs/README.md
  CLOTHLAB_TODO("ex04.1", "lessons/04-bending-springs/README.md");
  // END ex04.1
}

}  // namespace clothlab
