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
  // largest at one of its ends) plus |gust|. Norms that do not overflow where the squares would
  // (stableNorm), so that an absurd wind is named by its speed, not as infinite.
  double top_speed() const {
    double top = steady.stableNorm();
    for (const Vec3& w : table.y)
      top = std::max(top, w.stableNorm());
    return top + (gust_period > 0.0 ? gust.stableNorm() : 0.0);
  }
};

// The air (or fluid) an effect feels now: its velocity, and how that changes in time if it does.
// The air on triangles and a fluid's drag on particles both hold one.
class AirFlow {
 public:
  explicit AirFlow(const Vec3& v_air) : v_air_(v_air) {}
  const Vec3& velocity() const { return v_air_; }  // [m/s]
  // Changed while the simulation runs (a gust, a game's weather).
  void set_velocity(const Vec3& v_air) { v_air_ = v_air; }
  // Changes in time by itself (Wind above): from then on each step takes its own.
  void set_gusts(const Wind& gusts) { gusts_ = gusts; }
  void set_time(double t) {
    if (gusts_.changes()) v_air_ = gusts_.at(t);
  }
  // 1/2 M top^2 [J]: the kinetic energy of a mass M [kg] carried along at the flow's top speed,
  // what the flow can give a body (ForceEffect::energy_scale).
  double carried_energy(double mass) const {
    const double top = std::max(v_air_.norm(), gusts_.top_speed());
    return 0.5 * mass * top * top;
  }

 private:
  Vec3 v_air_;  // [m/s]
  Wind gusts_;  // how it changes in time, if it does
};

}  // namespace clothlab
