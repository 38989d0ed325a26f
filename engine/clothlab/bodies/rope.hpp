// rope.hpp: a rope, a chain of particles joined one to the next.
//
//   0 -- 1 -- 2 -- 3 -- ...     springs between neighbours (k, k+1);
//                               bending springs two apart (k, k+2) resist folding.
#pragma once

#include <vector>

#include "clothlab/bodies/cloth.hpp"

namespace clothlab {

struct Rope {
  Index first = 0;  // index of the rope's first particle
  Index count = 0;  // particles in the rope
};

struct RopeSpec {
  Vec3 start = Vec3::Zero();       // first particle [m]
  Vec3 end = Vec3(1.0, 0.0, 0.0);  // last particle [m]
  Index particles = 10;            // at least 2
  double mass = 1.0;               // total mass [kg], shared equally
};

// Appends the rope's particles, evenly spaced from start to end, at rest.
Rope add_rope(Particles& p, const RopeSpec& spec);

// Rope-local index pairs (k, k+1), and (k, k+2) for bending.
std::vector<IndexPair> rope_pairs(Index count);
std::vector<IndexPair> rope_bending_pairs(Index count);

}  // namespace clothlab
