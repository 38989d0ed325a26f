// Lesson 10, collision detection: the exercise kernels.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`, and
// watch a towel fold over a line on your code with
//   ./build/clothlab-student run lessons/10-collision-detection/towel-on-a-line.toml
// Every symbol is explained in lessons/10-collision-detection/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include <cmath>
#include <cstdint>

#include "clothlab/after_step/self_collision.hpp"
#include "clothlab/after_step/spatial_hash.hpp"
#include "clothlab/core/not_implemented.hpp"

namespace clothlab {

// Exercise ex10.1: the cell of edge h that holds x (see spatial_hash.hpp).
//   ix = floor(x / h),  iy = floor(y / h),  iz = floor(z / h)
// Hints:
//   1. std::floor, then a cast to std::int64_t. A cast alone truncates toward zero: -0.4 would
//      land in cell 0 with 0.4, and cell 0 would be twice as wide as the others.
//   2. A point exactly on a cell's lower face is in that cell: floor(0.5 / 0.25) = 2.
Cell cell_of(const Vec3& x, double h) {
  // BEGIN ex10.1: see lessons/10-collision-detection/README.md
  // floor, not a cast: a cast truncates toward zero and puts -0.4 h into cell 0.
  return {static_cast<std::int64_t>(std::floor(x.x() / h)),
          static_cast<std::int64_t>(std::floor(x.y() / h)),
          static_cast<std::int64_t>(std::floor(x.z() / h))};
  // END ex10.1
}

// Exercise ex10.1: the slot of cell c in a table of table_size slots.
//   hash = (ix * 73856093  xor  iy * 19349663  xor  iz * 83492791)  mod  table_size
// Hints:
//   3. Compute on std::uint64_t: cast each coordinate first (static_cast<std::uint64_t>(c.ix)),
//      then multiply. Products of 64-bit unsigned integers wrap around instead of overflowing,
//      and a negative coordinate becomes a large positive number.
//   4. With signed integers, -1 * 73856093 % 1000 is -93: a negative slot, outside the table.
//      Unsigned arithmetic never gives one.
std::size_t cell_hash(const Cell& c, std::size_t table_size) {
  // BEGIN ex10.1: see lessons/10-collision-detection/README.md
  // Unsigned 64-bit arithmetic wraps around: no overflow, and the slot is never negative.
  const std::uint64_t h = (static_cast<std::uint64_t>(c.ix) * 73856093u) ^
                          (static_cast<std::uint64_t>(c.iy) * 19349663u) ^
                          (static_cast<std::uint64_t>(c.iz) * 83492791u);
  return static_cast<std::size_t>(h % table_size);
  // END ex10.1
}

// Exercise ex10.2: the response of one pair of particles closer than the thickness (see
// self_collision.hpp). With d* = r2 - r1, d = |d*|, n = d* / d, w = w1 + w2:
//   C = thickness - d;  r1' = r1 - (w1 / w) C n,  r2' = r2 + (w2 / w) C n
//   u = v2 - v1;  if u . n < 0 (approaching):
//     j = (1 + e) |u . n|,  u_n = (u . n) n,  u_t = u - u_n
//     du = -(1 + e) u_n - (|u_t| <= mu_s j ? u_t : u_t mu_d j / |u_t|)
//     v1' = v1 - (w1 / w) du,  v2' = v2 + (w2 / w) du
// Hints:
//   1. Return `in` unchanged first for what cannot or need not move: both pinned (w = 0), at the
//      same point (d = 0, no direction n), and at least `thickness` apart (d >= thickness).
//   2. Push apart along n: particle 1 moves along -n, particle 2 along +n, the lighter one more.
//   3. A pair already moving apart (u . n >= 0) keeps its velocities: the positions are still
//      corrected, but there is nothing to bounce and no impulse for friction to use.
//   4. Friction only slows the sliding of one layer over the other, never reverses it.
PairState pair_response(const PairState& in, double w1, double w2, const SelfContact& contact) {
  // BEGIN ex10.2: see lessons/10-collision-detection/README.md
  const double w = w1 + w2;
  const Vec3 d_star = in.r2 - in.r1;
  const double d = d_star.norm();
  if (w == 0.0 || d == 0.0 || d >= contact.thickness) return in;
  const Vec3 n = d_star / d;               // from particle 1 toward particle 2
  const double C = contact.thickness - d;  // overlap [m]
  PairState out = in;
  out.r1 -= (w1 / w) * C * n;
  out.r2 += (w2 / w) * C * n;
  const Vec3 u = in.v2 - in.v1;
  const double un = u.dot(n);                // < 0: approaching
  if (un >= 0.0) return out;                 // moving apart already: nothing to bounce, no impulse
  const double j = (1.0 + contact.e) * -un;  // the bounce, per unit of reduced mass [m/s]
  const Vec3 u_t = u - un * n;
  const double ut = u_t.norm();
  // Static friction stops the sliding; dynamic friction takes mu_d j from it (mu_d j < |u_t|).
  const Vec3 friction = ut <= contact.mu_s * j ? Vec3(-u_t) : Vec3(-u_t * (contact.mu_d * j / ut));
  const Vec3 du = -(1.0 + contact.e) * un * n + friction;
  out.v1 -= (w1 / w) * du;
  out.v2 += (w2 / w) * du;
  return out;
  // END ex10.2
}

}  // namespace clothlab
