#include "clothlab/after_step/moving_pins.hpp"

#include <algorithm>
#include <numbers>

#include <Eigen/Geometry>

#include "clothlab/core/world.hpp"

namespace clothlab {

Vec3 PinPath::position(size_t k, double t) const {
  if (!offsets.empty()) return x0[k] + offsets.at(t);
  const Eigen::AngleAxisd turn(angular_speed() * t, axis);
  return centre + turn * Vec3(x0[k] - centre);
}

Vec3 PinPath::velocity(size_t k, double t) const {
  if (!offsets.empty()) return offsets.rate(t);
  return (angular_speed() * axis).cross(position(k, t) - centre);
}

double PinPath::top_speed() const {
  double top = 0.0;
  if (!offsets.empty()) {
    for (size_t s = 0; s + 1 < offsets.t.size(); ++s)
      top = std::max(top, offsets.rate(offsets.t[s]).norm());
    return top;
  }
  for (size_t k = 0; k < x0.size(); ++k)  // |w a x (x - c)| = w times the distance from the axis
    top = std::max(top, angular_speed() * axis.cross(Vec3(x0[k] - centre)).norm());
  return top;
}

void MovingPins::place(Particles& p, double t) const {
  for (const PinPath& path : paths_) {
    for (size_t k = 0; k < path.particles.size(); ++k) {
      p.x.col(path.particles[k]) = path.position(k, t);
      p.v.col(path.particles[k]) = path.velocity(k, t);
    }
  }
}

void MovingPins::apply(World& world, const StepTime& time) {
  place(world.particles, time.end());  // where the span it closes ends: t + dt after a step
}

double MovingPins::energy_scale(const Particles& p, double /*size*/) const {
  double top = 0.0;
  for (const PinPath& path : paths_)
    top = std::max(top, path.top_speed());
  return 0.5 * p.m.sum() * top * top;
}

}  // namespace clothlab
