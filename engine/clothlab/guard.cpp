#include "clothlab/guard.hpp"

#include <cmath>

#include <fmt/format.h>

#include "clothlab/world.hpp"

namespace clothlab {

namespace {

// The first column of a that is not finite or has a component beyond bound, or -1.
Index first_bad_column(const Matrix3X& a, double bound) {
  for (Index i = 0; i < a.cols(); ++i) {
    for (Index k = 0; k < 3; ++k) {
      // !(|a| <= bound) is also true for NaN, which compares false with everything.
      if (!(std::abs(a(k, i)) <= bound)) return i;
    }
  }
  return -1;
}

}  // namespace

void Guard::check(const World& world) const {
  const Particles& p = world.particles;
  // Fast path: one vectorised pass over each array. |a| <= bound is false for a NaN (every
  // comparison with NaN is false), so this one test catches NaN, infinity and runaway values.
  // Only a failing state pays for the search that finds which particle went wrong.
  const bool x_ok = (p.x.array().abs() <= max_position).all();
  const bool v_ok = (p.v.array().abs() <= max_speed).all();
  if (x_ok && v_ok) return;

  const bool position_bad = !x_ok;
  const Index i =
      position_bad ? first_bad_column(p.x, max_position) : first_bad_column(p.v, max_speed);
  const Vec3 value = position_bad ? Vec3(p.x.col(i)) : Vec3(p.v.col(i));
  const char* quantity = position_bad ? "position" : "velocity";
  const char* unit = position_bad ? "m" : "m/s";
  const double bound = position_bad ? max_position : max_speed;
  const std::string problem =
      value.allFinite()
          ? fmt::format("{} ({}, {}, {}) {} is beyond the guard's bound of {} {}", quantity,
                        value.x(), value.y(), value.z(), unit, bound, unit)
          : fmt::format("{} is not finite ({}, {}, {})", quantity, value.x(), value.y(), value.z());
  // The likely cause differs: a NaN is born from 0/0 (a zero length, two particles at the same
  // place); a value that grows past any bound is energy that the integrator keeps adding.
  const char* advice =
      value.allFinite()
          ? "A time step too large for the stiffness is the usual cause (try a smaller dt or "
            "another integrator); a force with the wrong sign does the same at any dt"
          : "A NaN usually comes from a division by zero (a zero length, two particles at the "
            "same place) or from values that overflowed after growing without bound";
  throw SimulationError(
      fmt::format("simulation blew up at step {} (t = {:.6g} s): particle {} {}. Effects in play: "
                  "{}. {}",
                  world.steps, world.t, i, problem, world.effects_in_play(), advice),
      world.steps, i);
}

}  // namespace clothlab
