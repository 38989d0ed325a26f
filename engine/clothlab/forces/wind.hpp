// wind.hpp: wind that changes in time, for the air on triangles and a fluid's drag (lesson 03).
//
//   v_air(t) = w(t) + gust sin(2 pi t / gust_period)
//
// w(t) is the steady wind, or keyframes of it (keyframes.hpp), linear in time between them; the
// sine adds gusts on top. The effects take v_air at the start of each step (ForceEffect::set_time)
// and hold it through the step: a step is short next to a gust.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "clothlab/core/keyframes.hpp"

namespace clothlab {

struct Wind {
  Vec3 steady = Vec3::Zero();  // w when there are no keyframes [m/s]
  Keyframes table;             // w at times [s], linear between; empty: the steady wind
  Vec3 gust = Vec3::Zero();    // amplitude of the sine [m/s]
  double gust_period = 0.0;    // [s]; 0: no sine

  bool changes() const { return !table.empty() || gust_period > 0.0; }

  Vec3 at(double t) const {  // v_air(t) [m/s]
    const Vec3 w = table.empty() ? steady : table.at(t);
    if (gust_period <= 0.0) return w;
    return w + std::sin(2.0 * std::numbers::pi * t / gust_period) * gust;
  }

  // A bound on |v_air(t)| [m/s]: the largest |w| (a keyframe's: |w| along a straight segment is
  // largest at one of its ends) plus |gust|.
  double top_speed() const {
    double top = steady.norm();
    for (const Vec3& w : table.y)
      top = std::max(top, w.norm());
    return top + (gust_period > 0.0 ? gust.norm() : 0.0);
  }
};

}  // namespace clothlab
