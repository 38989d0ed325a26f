// self_collision.hpp: cloth that does not pass through itself (lesson 10).
//
// Each particle is given a thickness: two particles of the cloth may come no closer than
// `thickness` [m] to each other, so a cloth that falls onto itself lies in layers instead of
// passing through itself. As for the ground (lesson 05), detection and response are separate:
//
// Detection. The broad phase (spatial_hash.hpp) sorts the particles into cells of edge
// `thickness` and offers as candidates only the particles of the 27 cells around each one; the
// narrow phase keeps the candidate pairs closer than `thickness`. Pairs that were already closer
// than that in the rest configuration (a cloth's grid neighbours when thickness > spacing) are
// left out: they are held apart by their springs, and pushing them to `thickness` would fight
// the springs every step.
//
// Response (exercise ex10.2), for a pair at r1, r2 with velocities v1, v2 and inverse masses
// w1, w2 [1/kg] (0: pinned), d = |r2 - r1| < thickness, n = (r2 - r1) / d:
//
//   positions  C = thickness - d, how deep the pair overlaps [m]
//              r1' = r1 - w1 / (w1 + w2) C n,   r2' = r2 + w2 / (w1 + w2) C n
//   velocities the relative velocity u = v2 - v1 has normal part u_n = (u . n) n and tangential
//              part u_t = u - u_n. If the pair approaches (u . n < 0), the change of u is, as
//              for the ground,  du = -(1 + e) u_n  (bounce with restitution e)
//                                  - u_t                       if |u_t| <= mu_s j  (static)
//                                  - u_t mu_d j / |u_t|        otherwise           (dynamic)
//              with j = (1 + e) |u . n|, shared by inverse mass:
//              v1' = v1 - w1 / (w1 + w2) du,   v2' = v2 + w2 / (w1 + w2) du.
//
// The split by inverse mass keeps momentum (m1 dv1 + m2 dv2 = (-du + du) / (w1 + w2) = 0) and
// the centre of mass, and never moves a pinned particle. Pushing one pair apart can push one of
// its particles into another: detection and response alternate up to `iterations` times a step,
// stopping as soon as detection finds no pair.
#pragma once

#include <cstddef>
#include <vector>

#include "clothlab/after_step/spatial_hash.hpp"
#include "clothlab/core/effect.hpp"

namespace clothlab {

// The contact constants of the [self_collision] table.
struct SelfContact {
  double thickness = 0.01;  // closest two particles may come [m]
  double e = 0.0;           // restitution of a pair, 0 to 1 (cloth does not bounce off itself)
  double mu_s = 0.3;        // static friction coefficient between layers
  double mu_d = 0.2;        // dynamic friction coefficient (<= mu_s)
};

// The state of two particles.
struct PairState {
  Vec3 r1 = Vec3::Zero(), v1 = Vec3::Zero();  // particle 1: position [m], velocity [m/s]
  Vec3 r2 = Vec3::Zero(), v2 = Vec3::Zero();  // particle 2
};

// Exercise ex10.2: the response of one pair with inverse masses w1, w2 [1/kg], as above. A pair at
// least `thickness` apart, a pair of two pinned particles (w1 + w2 = 0) and a pair at the same
// point (no direction n) come back unchanged.
PairState pair_response(const PairState& in, double w1, double w2, const SelfContact& contact);

class SelfCollision final : public PostStepEffect {
 public:
  // x_rest [m]: the particles where the scene built them, the rest configuration.
  SelfCollision(const SelfContact& contact, int iterations, const Matrix3X& x_rest)
      : contact_(contact), iterations_(iterations), x_rest_(x_rest) {}
  std::string_view name() const override { return "self_collision"; }
  void apply(World& world, const StepTime& time) override;

  // Detection alone: rebuilds the hash over x [m] (particles beyond +-bound [m] left out) and
  // returns every pair i < j closer than the thickness that is not excluded at rest.
  const std::vector<IndexPair>& detect(const Matrix3X& x, double bound);

  // Response alone: each pair, in the order given, through pair_response (exercise ex10.2), the
  // particles' x and v updated before the next pair is taken (Gauss-Seidel).
  void respond(Particles& p, const std::vector<IndexPair>& pairs) const;

  // True when particles i and j are closer than the thickness at rest, and so never collide.
  bool excluded(Index i, Index j) const {
    return (x_rest_.col(j) - x_rest_.col(i)).squaredNorm() <
           contact_.thickness * contact_.thickness;
  }

  const SelfContact& contact() const { return contact_; }
  const SpatialHash& hash() const { return hash_; }
  long hash_builds() const { return hash_.builds(); }
  std::size_t last_pairs() const { return last_pairs_; }     // found by the last step's first pass
  long total_pairs() const { return total_pairs_; }          // responses over every step so far
  int iterations() const { return iterations_; }             // most passes in one step
  int last_passes() const { return last_passes_; }           // detection passes of the last step
  double detect_seconds() const { return detect_seconds_; }  // [s] wall time in detection

 private:
  SelfContact contact_;
  int iterations_;  // most detect-and-respond passes in one step
  Matrix3X x_rest_;
  SpatialHash hash_;
  std::vector<IndexPair> pairs_;  // found by the last detection, reused every pass
  std::size_t last_pairs_ = 0;
  long total_pairs_ = 0;
  int last_passes_ = 0;
  double detect_seconds_ = 0.0;
};

}  // namespace clothlab
