#include "clothlab/integrators/vbd_vertex.hpp"

#include <Eigen/LU>  // the 3 x 3 inverse and determinant
#include <algorithm>

namespace clothlab {

VertexBlock vbd_vertex_block(const Vec3& x_i, const Vec3& x_i_start, const Vec3& y_i, double w_i,
                             double h, std::span<const VertexSpring> springs) {
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
}

Vec3 vbd_vertex_step(const Vec3& x_i, const Vec3& x_i_start, const Vec3& y_i, double w_i, double h,
                     std::span<const VertexSpring> springs) {
  if (w_i == 0.0) return Vec3::Zero();  // pinned: no step moves it
  const VertexBlock block = vbd_vertex_block(x_i, x_i_start, y_i, w_i, h, springs);
  const double scale = block.H.trace() / 3.0;  // H's mean eigenvalue [N/m]
  // Singular, or NaN from a bad input: no Newton step, the vertex stays (the header's guard).
  if (!(block.H.determinant() > kSingularBlock * scale * scale * scale)) return Vec3::Zero();
  return block.H.inverse() * block.f;
}

}  // namespace clothlab
