// types.hpp: the vector types every clothlab file speaks in.
//
// All physics is in SI units and double precision. Kernels take fixed-size Eigen types (Vec3);
// particle state is stored column-wise in Matrix3X arrays (one column per particle) so that
// the hot loops walk memory in order.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

namespace clothlab {

using Vec3 = Eigen::Vector3d;       // a position [m], velocity [m/s], force [N], ...
using Matrix3X = Eigen::Matrix3Xd;  // one Vec3 per column, one column per particle
using VectorX = Eigen::VectorXd;    // one scalar per particle

using Index = Eigen::Index;

// The unit vector along v (not zero, finite): v is first divided by its largest |component|, so
// that |v|^2 neither underflows to 0 (v = [0, 1e-170, 0]) nor overflows to infinity (1e170).
inline Vec3 unit_direction(const Vec3& v) {
  return (v / v.cwiseAbs().maxCoeff()).normalized();
}

}  // namespace clothlab
