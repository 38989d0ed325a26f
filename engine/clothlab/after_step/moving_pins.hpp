// moving_pins.hpp: pinned particles that follow a path, so a cloth can be waved or a rope swung
// (the lecture's "fixed points" that move).
//
// A pinned particle has inv_m = 0: no force moves it, and the integrator carries it along at
// its own velocity v. A path sets both after each step, at the step's end time t + dt
// (StepTime::end):
//
//   x(t) = x0 + d(t),   v(t) = d'(t)     keyframes: offsets d_k at times t_k, linear between
//   x(t) = c + R(w t) (x0 - c),          a circle: x0 turned about the axis a through c at
//   v(t) = w a x (x(t) - c)              w = 2 pi / period [rad/s] (right-hand rule about a)
//
// with x0 where the particle was built. Giving it the path's velocity matters: the dampers of
// its springs see the pin move, and an integrator's trial states carry it along the path.
#pragma once

#include <numbers>
#include <vector>

#include "clothlab/core/effect.hpp"
#include "clothlab/core/keyframes.hpp"

namespace clothlab {

struct PinPath {
  std::vector<Index> particles;  // the pinned particles it moves
  std::vector<Vec3> x0;          // where each was built [m]
  Keyframes offsets;             // d(t) [m]; empty: the path is a circle
  Vec3 centre = Vec3::Zero();    // a point on the circle's axis [m]
  Vec3 axis = Vec3::UnitZ();     // the axis, a unit vector
  double period = 0.0;           // one turn [s]

  Vec3 position(size_t k, double t) const;  // of particles[k] at time t [m]
  Vec3 velocity(size_t k, double t) const;  // [m/s]
  double top_speed() const;                 // the largest |v| on the path [m/s]
  double angular_speed() const { return 2.0 * std::numbers::pi / period; }  // a circle's w [rad/s]
};

class MovingPins final : public PostStepEffect {
 public:
  explicit MovingPins(std::vector<PinPath> paths) : paths_(std::move(paths)) {}
  std::string_view name() const override { return "moving_pins"; }
  // Places every pin where its path is when `time` closes: t + dt after a whole step.
  void apply(World& world, const StepTime& time) override;
  // Each pinned particle at its path's position and velocity at time t [s].
  void place(Particles& p, double t) const;
  // 1/2 M v_top^2: the kinetic energy of particles dragged along at the pins' top speed.
  double energy_scale(const Particles& p, double size) const override;
  const std::vector<PinPath>& paths() const { return paths_; }

 private:
  std::vector<PinPath> paths_;
};

}  // namespace clothlab
