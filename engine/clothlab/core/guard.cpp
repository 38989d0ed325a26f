#include "clothlab/core/guard.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "clothlab/core/integrator.hpp"
#include "clothlab/core/world.hpp"

namespace clothlab {

namespace {

// Whether |a| <= bound for every entry of columns [begin, end) of m (false if any is NaN). The
// loop has no early exit, so the compiler checks several entries at once; a state that passes
// reads every one anyway.
bool all_within(const Matrix3X& m, Index begin, Index end, double bound) {
  const double* a = m.data();
  long outside = 0;
  for (Index k = 3 * begin; k < 3 * end; ++k)
    outside += !(std::abs(a[k]) <= bound);
  return outside == 0;
}

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

// Why a particle's state is not finite, as far as the forces the step summed on it tell: an
// infinite force is a number that overflowed in a force effect (a wind, a stiffness, a mass or a
// distance too large for its square or product to be held); a NaN, a division by zero or an
// overflow on the way (infinity times zero, or less infinity). A pinned particle (1/m = 0) stays
// put under any finite force, but 0 times an infinite force is not a number: the pin is then
// where the NaN shows first, not where it was born.
std::string not_finite_advice(const Particles& p, Index i) {
  std::string advice =
      "A NaN usually comes from a division by zero (a zero length, two particles at the same "
      "place) or from values that overflowed after growing without bound";
  if (i >= p.f.cols() || p.f.col(i).allFinite()) return advice;
  const Vec3 f = p.f.col(i);
  const bool overflowed = (f.array().abs() == std::numeric_limits<double>::infinity()).any();
  advice = fmt::format("The forces the step summed on it were not finite ({}, {}, {}) N: ", f.x(),
                       f.y(), f.z());
  advice += overflowed ? "a force effect overflowed (a wind, a stiffness, a mass or a distance "
                         "too large for the numbers the step computes with)"
                       : "a force effect gave a NaN: a division by zero (a zero length, two "
                         "particles at the same place) or a number that overflowed on the way "
                         "(infinity times zero)";
  if (i < p.inv_m.size() && p.inv_m(i) == 0.0) {
    advice +=
        "; the particle is pinned (1/m = 0), which holds it against any finite force, not "
        "this one";
  }
  return advice;
}

// What makes a state run away with the world's method, said true for it. A method whose stable dt
// the springs bound (lesson 08) is usually past that bound; XPBD and the local/global solver have
// none there, so a smaller dt is no cure on the springs: the cause is elsewhere.
// A method whose iterations may stop short of solving very stiff springs (VBD with few sweeps)
// can also leave them stretched, their energy growing from step to step; there more iterations
// or a smaller dt (an easier solve each step) are the cure.
std::string likely_cause(const World& world, std::string_view symptom) {
  const std::string_view how =
      world.integrator ? world.integrator->springs_without_dt_limit() : std::string_view();
  if (how.empty()) return std::string(symptom);
  constexpr std::string_view elsewhere =
      "a force it takes explicitly that is far too strong for the step (wind, drag, gravitation "
      "between particles that come close), a pin path that moves too fast, or a force with the "
      "wrong sign";
  const std::string iterations = world.integrator->iterations_that_may_stop_short();
  if (iterations.empty()) {
    return fmt::format(
        "{} steps the springs {}, with no time-step limit from their stiffness, so a smaller dt "
        "is not the cure there: look for {}",
        world.integrator->name(), how, elsewhere);
  }
  return fmt::format(
      "{} steps the springs {}, with no time-step limit from their stiffness; but if they are "
      "very stiff, {} may leave them far from solved, their energy growing from step to step: "
      "more iterations, or a smaller dt (each step's solve is then easier), is the cure. Else "
      "look for {}",
      world.integrator->name(), how, iterations, elsewhere);
}

}  // namespace

bool Guard::within(const Matrix3X& x, const Matrix3X& v, Index begin, Index end) const {
  return all_within(x, begin, end, max_position) && all_within(v, begin, end, max_speed);
}

void Guard::check(const World& world, bool before_step) const {
  const Particles& p = world.particles;
  // Fast path: one vectorised pass over each array. |a| <= bound is false for a NaN (every
  // comparison with NaN is false), so this one test catches NaN, infinity and runaway values.
  // Only a failing state pays for the search that finds which particle went wrong.
  // Threads (World::threads) may share it, each checking a range of particles.
  std::atomic<bool> ok = true;
  world.for_particles([&](Index begin, Index end) {
    if (!within(p.x, p.v, begin, end)) ok = false;
  });
  if (ok) return;

  const Index bad_position = first_bad_column(p.x, max_position);
  const bool position_bad = bad_position >= 0;
  const Index i = position_bad ? bad_position : first_bad_column(p.v, max_speed);
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
  const std::string advice =
      value.allFinite()
          ? likely_cause(world,
                         "A time step too large for the stiffness is the usual cause (try a "
                         "smaller dt or another integrator); a force with the wrong sign does "
                         "the same at any dt")
          : not_finite_advice(p, i);
  if (before_step) {
    throw SimulationError(
        fmt::format("simulation blew up before step {} (t = {:.6g} s): particle {} {}, and it "
                    "was not after the last step: something outside the step (your own code, "
                    "or a change to the state between steps) put it there. Effects in play: {}",
                    world.steps + 1, world.t, i, problem, world.effects_in_play()),
        world.steps + 1, i);
  }
  throw SimulationError(
      fmt::format("simulation blew up at step {} (t = {:.6g} s): particle {} {}. Effects in play: "
                  "{}. {}",
                  world.steps, world.t, i, problem, world.effects_in_play(), advice),
      world.steps, i);
}

void Guard::start(const World& world) {
  const Particles& p = world.particles;
  std::vector<double> potentials;
  energy_start_ = world.kinetic_energy() + world.potential_energy(&potentials);
  effect_start_.clear();
  for (size_t e = 0; e < world.force_effects.size(); ++e)
    effect_start_.push_back({world.force_effects[e].get(), potentials[e]});
  double size = 0.0;
  if (p.size() > 0) size = (p.x.rowwise().maxCoeff() - p.x.rowwise().minCoeff()).norm();
  energy_scale_ = world.kinetic_energy();
  for (const auto& effect : world.force_effects)
    energy_scale_ += effect->energy_scale(p, p.x, size);
  for (const auto& effect : world.post_step_effects)
    energy_scale_ += effect->energy_scale(p, size);
  x_start_ = p.x;
  released_ = 0.0;
}

void Guard::check_energy(const World& world) const {
  const Particles& p = world.particles;
  // Each effect's term kept for what the fields have released: |U(x) - U(x_start)|, U(x_start)
  // as start() found it if the field is still at its place in the list, else computed now.
  std::vector<double> potentials;
  const double energy = world.kinetic_energy() + world.potential_energy(&potentials);
  if (x_start_.cols() == p.size()) {
    double released = 0.0;
    for (size_t e = 0; e < world.force_effects.size(); ++e) {
      const ForceEffect& effect = *world.force_effects[e];
      if (!effect.external_field()) continue;
      const bool kept = e < effect_start_.size() && effect_start_[e].effect == &effect;
      released += std::abs(potentials[e] -
                           (kept ? effect_start_[e].energy : effect.potential_energy(p, x_start_)));
    }
    released_ = std::max(released_, released);
  }
  const double allowed = max_energy_growth * energy_scale();
  // !(gain <= allowed) also catches a NaN energy.
  if (energy - energy_start_ <= allowed) return;
  // Name the particle that moves fastest: where the energy went.
  Index fastest = 0;
  if (p.size() > 0) p.v.colwise().squaredNorm().maxCoeff(&fastest);
  throw SimulationError(
      fmt::format("simulation ran away at step {} (t = {:.6g} s): the total energy rose from "
                  "{:.6g} J to {:.6g} J, more than max_energy_growth = {} times the scene's "
                  "energy scale of {:.3g} J, energy that no force put in; particle {} moves "
                  "fastest ({:.3g} m/s). Effects in play: {}. {}; raise [guard] "
                  "max_energy_growth if the energy is meant to grow",
                  world.steps, world.t, energy_start_, energy, max_energy_growth, energy_scale(),
                  fastest, p.v.col(fastest).norm(), world.effects_in_play(),
                  likely_cause(world,
                               "The integrator is adding energy: dt is above its stability "
                               "limit, or the method gains energy at any dt on undamped springs "
                               "(explicit Euler, midpoint). `clothlab validate` estimates the "
                               "limit")),
      world.steps, fastest);
}

}  // namespace clothlab
