#include "clothlab/after_step/self_collision.hpp"

#include <chrono>

#include "clothlab/core/stop.hpp"
#include "clothlab/core/world.hpp"

namespace clothlab {

const std::vector<IndexPair>& SelfCollision::detect(const Matrix3X& x, double bound) {
  const auto start = std::chrono::steady_clock::now();
  const double h = contact_.thickness;  // cells as large as the thickness: neighbours suffice
  hash_.build(x, h, bound);
  pairs_.clear();
  hash_.for_each_pair(x, h, [&](Index i, Index j) {
    if (!excluded(i, j)) pairs_.emplace_back(i, j);
  });
  detect_seconds_ +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return pairs_;
}

void SelfCollision::apply(World& world, const StepTime& /*time*/) {
  Particles& p = world.particles;
  last_passes_ = 0;
  last_pairs_ = 0;
  for (int pass = 0; pass < iterations_; ++pass) {
    stop_point();  // many passes of a big cloth can take minutes (core/stop.hpp)
    detect(p.x, world.guard.max_position);
    ++last_passes_;
    if (pass == 0) last_pairs_ = pairs_.size();
    if (pairs_.empty()) break;  // nothing closer than the thickness: done
    respond(p, pairs_);
    total_pairs_ += static_cast<long>(pairs_.size());
  }
}

void SelfCollision::respond(Particles& p, const std::vector<IndexPair>& pairs) const {
  // Gauss-Seidel, as in strain limiting: each pair sees the corrections of the pairs before it.
  for (const auto& [i, j] : pairs) {
    const double w1 = p.inv_m[i], w2 = p.inv_m[j];
    if (w1 + w2 == 0.0) continue;  // two pinned particles: nothing can move
    const PairState out =
        pair_response({p.x.col(i), p.v.col(i), p.x.col(j), p.v.col(j)}, w1, w2, contact_);
    p.x.col(i) = out.r1;
    p.v.col(i) = out.v1;
    p.x.col(j) = out.r2;
    p.v.col(j) = out.v2;
  }
}

}  // namespace clothlab
