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

}  // namespace clothlab
