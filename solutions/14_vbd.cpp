// Lesson 14, Vertex Block Descent: the exercise kernel.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`, and
// watch a cloth stepped by your vertex steps with
//   ./build/clothlab-student run lessons/14-vbd/stiff-sheet.toml
// Every symbol is explained in lessons/14-vbd/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include <Eigen/LU>  // the 3 x 3 inverse and determinant
#include <algorithm>

#include "clothlab/core/not_implemented.hpp"
#include "clothlab/integrators/vbd_vertex.hpp"

namespace clothlab {

// Exercise ex14.1, part 1: the vertex's force f = -grad G_i and Hessian H = hess G_i (see
// vbd_vertex.hpp), with d = x_i - x_j, l = |d|, u = d / l for each spring:
//   inertia:  f += -m_i/h^2 (x_i - y_i)          H += m_i/h^2 I          (m_i/h^2 = 1/(w_i h^2))
//   spring:   f += -ks (l - l0) u                 H += ks (u u^T + max(0, 1 - l0/l) (I - u u^T))
//   damper:   f += -(1/h) D (dx_i - dx_j)         H += D / h,   D = kd (the same shape matrix)
// Hints:
//   1. A massless vertex has w_i infinite: 1/(w_i h^2) is then 0, no inertia term, no NaN.
//   2. A spring whose ends coincide (l = 0) has no direction: it adds nothing.
//   3. The max(0, ...) is what keeps H definite for a compressed spring (l < l0): without it the
//      stiffness across the spring is negative (the README's "Made definite").
//   4. dx_i = x_i - x_i_start and dx_j = x_j - x_j_start: how far each end has moved this step.
VertexBlock vbd_vertex_block(const Vec3& x_i, const Vec3& x_i_start, const Vec3& y_i, double w_i,
                             double h, std::span<const VertexSpring> springs) {
  // BEGIN ex14.1: see lessons/14-vbd/README.md
  const Mat3 I = Mat3::Identity();
  // Inertia: m_i/h^2 = 1 / (w_i h^2), which is 0 for a massless vertex (w_i infinite).
  const double inertia = 1.0 / (w_i * h * h);  // [N/m]
  VertexBlock block{-inertia * (x_i - y_i), inertia * I};
  const Vec3 dx_i = x_i - x_i_start;
  for (const VertexSpring& s : springs) {
    const Vec3 d = x_i - s.x_j;
    const double l = d.norm();
    if (l == 0.0) continue;  // no direction: no force, no stiffness
    const Vec3 u = d / l;
    const Mat3 along = u * u.transpose();  // projects onto the spring's direction
    // ks (1 - l0/l) across the spring, clamped at 0 for a compressed one (the header says why).
    const double across = std::max(0.0, 1.0 - s.l0 / l);
    const Mat3 shape = along + across * (I - along);
    block.f += -s.ks * (l - s.l0) * u;
    block.H += s.ks * shape;
    // Rayleigh damping on the relative displacement over the step: -(kd/h) shape (dx_i - dx_j).
    if (s.kd != 0.0) {
      const Mat3 D = s.kd * shape;  // [N s/m]
      block.f += -(D * (dx_i - (s.x_j - s.x_j_start))) / h;
      block.H += D / h;
    }
  }
  return block;
  // END ex14.1
}

// Exercise ex14.1, part 2: the vertex's Newton step dx = H^-1 f.
// Hints:
//   1. A pinned vertex (w_i = 0) never moves: return zero before anything else.
//   2. The guard: H is singular when det(H) <= kSingularBlock (trace(H) / 3)^3; return zero
//      then, never NaN. Write the test so that a NaN in H also fails it (!(det > bound)).
//   3. Eigen's H.inverse() * f (or H.ldlt().solve(f)) solves the 3 x 3 system.
Vec3 vbd_vertex_step(const Vec3& x_i, const Vec3& x_i_start, const Vec3& y_i, double w_i, double h,
                     std::span<const VertexSpring> springs) {
  // BEGIN ex14.1: see lessons/14-vbd/README.md
  if (w_i == 0.0) return Vec3::Zero();  // pinned: no step moves it
  const VertexBlock block = vbd_vertex_block(x_i, x_i_start, y_i, w_i, h, springs);
  const double scale = block.H.trace() / 3.0;  // H's mean eigenvalue [N/m]
  // Singular, or NaN from a bad input: no Newton step, the vertex stays (the header's guard).
  if (!(block.H.determinant() > kSingularBlock * scale * scale * scale)) return Vec3::Zero();
  return block.H.inverse() * block.f;
  // END ex14.1
}

}  // namespace clothlab
