#include "clothlab/particles.hpp"

#include <cassert>
#include <cmath>

namespace clothlab {

Index Particles::add(const Vec3& position, const Vec3& velocity, double mass) {
  assert(mass > 0 && std::isfinite(mass));
  const Index i = size();
  x.conservativeResize(3, i + 1);
  v.conservativeResize(3, i + 1);
  f.conservativeResize(3, i + 1);
  m.conservativeResize(i + 1);
  inv_m.conservativeResize(i + 1);
  x.col(i) = position;
  v.col(i) = velocity;
  f.col(i).setZero();
  m[i] = mass;
  inv_m[i] = 1.0 / mass;
  return i;
}

}  // namespace clothlab
