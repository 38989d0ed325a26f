// particles.hpp: the state of every particle, stored as parallel arrays.
//
// Lecture: a particle has a mass m, a position r, a velocity v and a force accumulator f.
// Instead of an array of Particle objects we keep one array per quantity (structure of
// arrays): column i of each matrix belongs to particle i. Loops over "all positions" then read
// memory in order, which is what makes the later layers fast.
#pragma once

#include "clothlab/core/types.hpp"

namespace clothlab {

// The position r [m] and velocity v [m/s] of one particle: what a one-particle kernel returns
// (lesson 01's Euler steps, lesson 05's collision response).
struct PointState {
  Vec3 r;
  Vec3 v;
};

struct Particles {
  Matrix3X x;     // positions r [m]
  Matrix3X v;     // velocities v [m/s]
  Matrix3X f;     // force accumulators f [N], cleared at the start of every step
  VectorX m;      // masses m [kg]
  VectorX inv_m;  // inverse masses 1/m [1/kg]; 0: no force can accelerate the particle
                  // (a pinned particle has inv_m = 0 and v = 0, so it never moves)

  Index size() const { return x.cols(); }

  // Appends one particle and returns its index. mass [kg] must be positive and finite.
  Index add(const Vec3& position, const Vec3& velocity, double mass);

  // Appends n particles of the given mass [kg] at the origin, at rest, and returns the index of
  // the first. Builders of large grids use this: the arrays grow once, not once per particle.
  Index grow(Index n, double mass);
};

// Sets particles [first, first + count) moving as one rigid body: v = v0 + w x (r - c), with v0
// [m/s] the velocity of their centre of mass c = sum m r / sum m, and w [rad/s] their angular
// velocity about it. Their momentum is then M v0, since sum m (r - c) = 0.
void start_moving(Particles& p, Index first, Index count, const Vec3& v0, const Vec3& w);

}  // namespace clothlab
