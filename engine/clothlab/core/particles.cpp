#include "clothlab/core/particles.hpp"

#include <cassert>
#include <cmath>

namespace clothlab {

Index Particles::add(const Vec3& position, const Vec3& velocity, double mass) {
  const Index i = grow(1, mass);
  x.col(i) = position;
  v.col(i) = velocity;
  return i;
}

Index Particles::grow(Index n, double mass) {
  assert(mass > 0 && std::isfinite(mass) && n >= 0);
  const Index first = size();
  const Index count = first + n;
  x.conservativeResize(3, count);
  v.conservativeResize(3, count);
  f.conservativeResize(3, count);
  m.conservativeResize(count);
  inv_m.conservativeResize(count);
  x.rightCols(n).setZero();
  v.rightCols(n).setZero();
  f.rightCols(n).setZero();
  m.tail(n).setConstant(mass);
  inv_m.tail(n).setConstant(1.0 / mass);
  return first;
}

void start_moving(Particles& p, Index first, Index count, const Vec3& v0, const Vec3& w) {
  const VectorX m = p.m.segment(first, count);
  const Vec3 c = p.x.middleCols(first, count) * m / m.sum();  // sum m r / sum m
  for (Index i = first; i < first + count; ++i)
    p.v.col(i) = v0 + w.cross(Vec3(p.x.col(i) - c));
}

}  // namespace clothlab
