#include "scene/scene_tables.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/after_step/moving_pins.hpp"
#include "clothlab/after_step/plasticity.hpp"
#include "clothlab/after_step/self_collision.hpp"
#include "clothlab/after_step/strain_limiting.hpp"
#include "clothlab/after_step/tearing.hpp"
#include "clothlab/bodies/solid.hpp"
#include "clothlab/core/threads.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/bending.hpp"
#include "clothlab/forces/damping.hpp"
#include "clothlab/forces/gravitation.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/local_global.hpp"
#include "clothlab/integrators/methods.hpp"
#include "clothlab/integrators/vbd.hpp"
#include "clothlab/integrators/xpbd.hpp"
#include "fast/float_room.hpp"

namespace clothlab {

namespace {

// The smallest mass a particle may have [kg]: the engine divides by it (inv_m = 1/m), and below
// the smallest normal double, 2.2e-308, the inverse overflows to infinity.
constexpr double kMinParticleMass = std::numeric_limits<double>::min();

// Refuses a share of mass too small to divide by; `what` says where the share came from.
void check_particle_mass(SceneTable& t, std::string_view key, double m, const std::string& what) {
  if (m < kMinParticleMass) {
    t.fail(key, fmt::format("{} is {} kg, too small to divide by; expected at least {:.2g} kg a "
                            "particle",
                            what, m, kMinParticleMass));
  }
}

// The largest number a 32-bit float holds (3.4e38): the page and the .npy files keep floats, and
// the float room computes in them.
constexpr double kFloatMax = std::numeric_limits<float>::max();

// Notes in `scene` the first start past what a float holds, at `key`: a position (x [m]) or a
// velocity (v [m/s]) that the guard's widened bounds let through. A run that would write it to
// a file of floats refuses it there (Scene::position_beyond_float).
void note_beyond_float(const SceneTable& t, std::string_view key, Scene& scene, const Vec3& x,
                       bool position, std::string_view what) {
  std::optional<SceneWarning>& note =
      position ? scene.position_beyond_float : scene.velocity_beyond_float;
  if (note || (x.array().abs() <= kFloatMax).all()) return;
  note = t.at(key, position ? fmt::format("{} starts at ({}, {}, {}) m, beyond what a 32-bit float "
                                          "holds ({:.6g}), which the page and positions.npy keep; "
                                          "expected |x|, |y|, |z| <= {:.6g} m, or a run that "
                                          "writes the CSV files alone (--no-html, format = "
                                          "\"csv\")",
                                          what, x.x(), x.y(), x.z(), kFloatMax, kFloatMax)
                            : fmt::format("{} starts at velocity ({}, {}, {}) m/s, beyond what a "
                                          "32-bit float holds ({:.6g}), which velocities.npy "
                                          "keeps; expected each component within {:.6g} m/s, or "
                                          "velocities in velocities.csv (format = \"csv\")",
                                          what, x.x(), x.y(), x.z(), kFloatMax, kFloatMax));
}

// The guard stops a run at its first step if a particle starts beyond its bounds, so such a scene
// is refused here, where the line can be named; this also keeps a huge spacing or coordinate from
// overflowing to infinity. [guard] is read before any particle.
void check_within_guard(SceneTable& t, std::string_view key, Scene& scene, Index i,
                        std::string_view what) {
  const double bound = scene.world.guard.max_position;
  const Vec3 x = scene.world.particles.x.col(i);
  // !(|x| <= bound) also catches an infinity, as in Guard::check.
  if (!(x.array().abs() <= bound).all()) {
    t.fail(key, fmt::format("{} starts at ({}, {}, {}) m, beyond the guard's max_position = {} m; "
                            "expected |x|, |y|, |z| <= {} m (a larger max_position in [guard] "
                            "allows more)",
                            what, x.x(), x.y(), x.z(), bound, bound));
  }
  note_beyond_float(t, key, scene, x, true, what);
}

// [[particle]]: one point mass (lesson 01).
void read_particle(SceneTable& t, Scene& scene) {
  const Vec3 x = t.required_vec3("position", "m");
  const Vec3 v = t.vec3("velocity", "m/s", Vec3::Zero());
  const double m = t.required_number("mass", Range::positive("kg"));
  check_particle_mass(t, "mass", m, fmt::format("'mass' in {}", t.display_name()));
  const bool pinned = t.boolean("pinned", false);
  if (pinned && v != Vec3::Zero()) {
    // pin() sets v = 0: a velocity given here would be dropped without a word.
    t.fail("velocity", fmt::format("{} is pinned but has velocity ({}, {}, {}) m/s; expected no "
                                   "velocity (a pinned particle never moves)",
                                   t.display_name(), v.x(), v.y(), v.z()));
  }
  const double max_speed = scene.world.guard.max_speed;
  if (!(v.array().abs() <= max_speed).all()) {
    t.fail("velocity", fmt::format("{} starts at velocity ({}, {}, {}) m/s, beyond the guard's "
                                   "max_speed = {} m/s; expected each component within {} m/s (a "
                                   "larger max_speed in [guard] allows more)",
                                   t.display_name(), v.x(), v.y(), v.z(), max_speed, max_speed));
  }
  note_beyond_float(t, "velocity", scene, v, false, t.display_name());
  const Index i = scene.world.particles.add(x, v, m);
  check_within_guard(t, "position", scene, i, t.display_name());
  if (pinned) pin(scene.world.particles, i);
}

// `velocity` [m/s] and `spin` [rad/s] of a body, particles [first, first + count): they start
// moving as one rigid body, v = velocity + spin x (r - c) about their centre of mass c (lesson
// 09). Called before the pins, which then stop the particles they hold.
void read_body_motion(SceneTable& t, Scene& scene, Index first, Index count,
                      std::string_view what) {
  const Vec3 v0 = t.vec3("velocity", "m/s", Vec3::Zero());
  const Vec3 w = t.vec3("spin", "rad/s", Vec3::Zero());
  if (v0 == Vec3::Zero() && w == Vec3::Zero()) return;
  Particles& p = scene.world.particles;
  start_moving(p, first, count, v0, w);
  const double max_speed = scene.world.guard.max_speed;
  for (Index i = first; i < first + count; ++i) {
    const Vec3 v = p.v.col(i);
    if ((v.array().abs() <= max_speed).all()) continue;
    t.fail(t.has("spin") ? "spin" : "velocity",
           fmt::format("{} particle {} starts at velocity ({}, {}, {}) m/s, beyond the guard's "
                       "max_speed = {} m/s; expected each component within {} m/s (a larger "
                       "max_speed in [guard] allows more)",
                       what, i - first, v.x(), v.y(), v.z(), max_speed, max_speed));
  }
  for (Index i = first; i < first + count; ++i) {
    note_beyond_float(t, t.has("spin") ? "spin" : "velocity", scene, p.v.col(i), false,
                      fmt::format("{} particle {}", what, i - first));
  }
}

// Warns at the first element of the array 'pins' that repeats an earlier one: a particle is
// pinned once, so the repeat does nothing and is likely a typo for another index. Sorting the
// (index, place) pairs finds repeats in O(k log k) for k pins, not by comparing every pair.
void warn_repeated_pins(SceneTable& t, Scene& scene, const std::vector<Index>& pins) {
  std::vector<std::pair<Index, size_t>> sorted(pins.size());
  for (size_t k = 0; k < pins.size(); ++k)
    sorted[k] = {pins[k], k};
  std::sort(sorted.begin(), sorted.end());
  size_t repeats = 0, first = 0, repeat = pins.size();  // repeat: the earliest repeating place
  size_t run = 0;  // where the run of equal indices that sorted[k] is in starts
  for (size_t k = 1; k < sorted.size(); ++k) {
    if (sorted[k].first != sorted[k - 1].first) {
      run = k;
      continue;
    }
    ++repeats;
    if (sorted[k].second < repeat) {
      repeat = sorted[k].second;
      first = sorted[run].second;  // the same index's first place
    }
  }
  if (repeats == 0) return;
  t.warn(
      scene, "pins",
      fmt::format("'pins[{}]' in {} pins particle {} again, as 'pins[{}]' does ({} repeat{} in "
                  "all); a particle is pinned once, so a repeat does nothing: remove it, or "
                  "write the index you meant",
                  repeat, t.display_name(), pins[repeat], first, repeats, repeats == 1 ? "" : "s"),
      repeat);
}

// Pins of a builder: a name (e.g. "top-corners") or an array of local indices below `count`.
std::vector<Index> read_pins(
    SceneTable& t, Scene& scene, Index count,
    const std::function<bool(std::string_view, std::vector<Index>&)>& named,
    std::string_view names) {
  std::vector<Index> pins;
  if (t.has("pins") && !t.is_string("pins") && !t.is_array("pins")) {
    t.fail("pins", fmt::format("'pins' in {} is {}; expected a pin set ({}) or an array of "
                               "particle indices",
                               t.display_name(), t.type_name("pins"), names));
  }
  if (t.is_string("pins")) {
    const std::string name = *t.string("pins");
    if (!named(name, pins)) {
      t.fail("pins", fmt::format("unknown pin set '{}' in {}; expected one of: {}, or an array "
                                 "of particle indices",
                                 name, t.display_name(), names));
    }
  } else {
    for (long i : t.integer_list("pins", 0, static_cast<long>(count) - 1, "pin index")) {
      pins.push_back(i);
    }
    warn_repeated_pins(t, scene, pins);  // a pin set never repeats; an array may
  }
  return pins;
}

// Keyframes from `times_key` (increasing times [s]) and `values_key` (one [x, y, z] [unit] a
// time), both given or neither (then none).
Keyframes read_keyframes(SceneTable& t, std::string_view times_key, std::string_view values_key,
                         std::string_view unit) {
  Keyframes frames;
  if (!t.has(times_key) && !t.has(values_key)) return frames;
  if (!t.has(times_key)) {
    t.fail(values_key, fmt::format("{} has '{}' but no '{}'; expected {} = [t0, t1, ...] [s], one "
                                   "time for each of its values",
                                   t.display_name(), values_key, times_key, times_key));
  }
  if (!t.has(values_key)) {
    t.fail(times_key, fmt::format("{} has '{}' but no '{}'; expected {} = [[x, y, z], ...] [{}], "
                                  "one for each time",
                                  t.display_name(), times_key, values_key, values_key, unit));
  }
  frames.t = t.number_list(times_key, Range::non_negative("s"), "time");
  frames.y = t.vec3_list(values_key, unit);
  if (frames.t.empty()) {
    t.fail(times_key, fmt::format("'{}' in {} is empty; expected at least one time [s]", times_key,
                                  t.display_name()));
  }
  for (size_t k = 1; k < frames.t.size(); ++k) {
    if (frames.t[k] > frames.t[k - 1]) continue;
    t.fail(times_key, fmt::format("'{}[{}]' in {} is {} s, not after '{}[{}]' = {} s; expected "
                                  "increasing times",
                                  times_key, k, t.display_name(), frames.t[k], times_key, k - 1,
                                  frames.t[k - 1]));
  }
  if (frames.y.size() != frames.t.size()) {
    t.fail(values_key, fmt::format("{} has {} {} for {} times; expected one for each time",
                                   t.display_name(), frames.y.size(), values_key, frames.t.size()));
  }
  return frames;
}

// A pin path must keep its particles within the guard's bounds: past them the guard stops the run
// at the step the path gets there (at the start, before step 1, blaming "something outside the
// step"). The extremes, coordinate by coordinate: keyframes are linear between their offsets, so
// a pin is farthest at an offset, the farthest of all where the farthest start meets the largest
// offset, and fastest on a segment; a circle of radius r about its centre c' (the start's foot
// on the axis a) reaches |c'_j| + r sqrt(1 - a_j^2) along coordinate j, at speeds up to w times
// the same radius.
void check_path_within_guard(SceneTable& t, const Scene& scene, const PinPath& path) {
  const Guard& guard = scene.world.guard;
  // "WHAT (x, y, z) m, beyond the guard's max_position = ...", at `key`.
  const auto beyond = [&](std::string_view key, const std::string& what, const Vec3& v,
                          bool position) {
    const char* name = position ? "max_position" : "max_speed";
    const char* unit = position ? "m" : "m/s";
    const double bound = position ? guard.max_position : guard.max_speed;
    t.fail(key, fmt::format("{} ({}, {}, {}) {}, beyond the guard's {} = {} {}; expected each "
                            "component within {} {} (a larger {} in [guard] allows more)",
                            what, v.x(), v.y(), v.z(), unit, name, bound, unit, bound, unit, name));
  };
  const auto within = [](const Vec3& v, double bound) { return (v.array().abs() <= bound).all(); };
  if (path.offsets.empty()) {
    const double w = path.angular_speed();
    for (size_t k = 0; k < path.particles.size(); ++k) {
      const Vec3 foot = path.centre + (path.x0[k] - path.centre).dot(path.axis) * path.axis;
      const double r = (path.x0[k] - foot).norm();
      Vec3 far, fast;
      for (int j = 0; j < 3; ++j) {
        const double across = r * std::sqrt(std::max(0.0, 1.0 - path.axis[j] * path.axis[j]));
        far[j] = std::abs(foot[j]) + across;
        fast[j] = w * across;
      }
      const std::string circle = fmt::format("the circle of pin {} (particle {}) in {}", k,
                                             path.particles[k], t.display_name());
      if (!within(far, guard.max_position))
        beyond("centre", circle + " reaches |x|, |y|, |z| up to", far, true);
      if (!within(fast, guard.max_speed))
        beyond("period", circle + " moves it at |vx|, |vy|, |vz| up to", fast, false);
    }
    return;
  }
  const Keyframes& d = path.offsets;
  for (int j = 0; j < 3; ++j) {
    // The pins that start farthest each way along j, and the offsets that take them farthest.
    size_t lo = 0, hi = 0, dlo = 0, dhi = 0;
    for (size_t k = 1; k < path.x0.size(); ++k) {
      if (path.x0[k][j] < path.x0[lo][j]) lo = k;
      if (path.x0[k][j] > path.x0[hi][j]) hi = k;
    }
    for (size_t f = 1; f < d.y.size(); ++f) {
      if (d.y[f][j] < d.y[dlo][j]) dlo = f;
      if (d.y[f][j] > d.y[dhi][j]) dhi = f;
    }
    for (const auto& [k, f] : {std::pair{lo, dlo}, std::pair{hi, dhi}}) {
      const Vec3 at = path.x0[k] + d.y[f];
      if (within(at, guard.max_position)) continue;
      beyond("offsets",
             fmt::format("'offsets[{}]' in {} (t = {} s) takes pin {} (particle {}) to", f,
                         t.display_name(), d.t[f], k, path.particles[k]),
             at, true);
    }
  }
  for (size_t f = 0; f + 1 < d.t.size(); ++f) {
    const Vec3 v = d.rate(d.t[f]);
    if (within(v, guard.max_speed)) continue;
    beyond("offsets",
           fmt::format("from 'offsets[{}]' to 'offsets[{}]' in {} (t = {} to {} s), the path "
                       "moves at",
                       f, f + 1, t.display_name(), d.t[f], d.t[f + 1]),
           v, false);
  }
}

// A body's [[NAME.pin_path]] tables: pins that follow keyframed offsets or turn on a circle
// (moving_pins.hpp). The particles they name are pinned; they are put on their paths once the
// whole scene is read, so that the springs' rest lengths are those of the body as built.
void read_pin_paths(SceneTable& body, Scene& scene, Index first, Index count,
                    const std::function<bool(std::string_view, std::vector<Index>&)>& named,
                    std::string_view names) {
  if (!body.has("pin_path")) return;
  Particles& p = scene.world.particles;
  // The body's fixed pins ('pins'), read before its paths: a path that also holds one of them
  // moves it, and the fixed pin does nothing.
  std::vector<bool> fixed(static_cast<size_t>(count));
  for (Index i = 0; i < count; ++i)
    fixed[static_cast<size_t>(i)] = p.inv_m[first + i] == 0.0;
  // The particles on the body's earlier paths, one mark each: comparing each pin with every
  // earlier path's pins made 10^12 comparisons for two paths of 10^6 pins.
  std::vector<bool> on_path(static_cast<size_t>(count));
  for (SceneTable& t : body.tables("pin_path")) {
    t.check_keys("pins times offsets centre axis period");
    if (!t.has("pins")) {
      t.fail("pins", fmt::format("{} has no 'pins'; expected pins = a pin set ({}) or an array of "
                                 "particle indices",
                                 t.display_name(), names));
    }
    PinPath path;
    const std::vector<Index> pins = read_pins(t, scene, count, named, names);
    const auto is_fixed = [&](Index i) { return fixed[static_cast<size_t>(i)]; };
    if (const auto both = std::count_if(pins.begin(), pins.end(), is_fixed); both > 0) {
      const auto k =
          static_cast<size_t>(std::find_if(pins.begin(), pins.end(), is_fixed) - pins.begin());
      t.warn(scene, "pins",
             fmt::format("particle {} is pinned by the body's 'pins' and moved by {} ({} such "
                         "particle{} in all); the path moves it, so its fixed pin does nothing: "
                         "remove it from one of the two",
                         pins[k], t.display_name(), both, both == 1 ? "" : "s"),
             t.is_array("pins") ? std::optional<size_t>(k) : std::nullopt);
    }
    for (Index i : pins) {
      if (on_path[static_cast<size_t>(i)]) {
        t.fail("pins", fmt::format("particle {} of {} is on an earlier path already; expected "
                                   "each particle on one path at most",
                                   i, t.display_name()));
      }
      pin(p, first + i);
      path.particles.push_back(first + i);
      path.x0.push_back(p.x.col(first + i));
    }
    if (path.particles.empty()) {
      t.fail("pins", fmt::format("{} moves no particle; expected at least one in 'pins'",
                                 t.display_name()));
    }
    const bool circle = t.has("centre") || t.has("axis") || t.has("period");
    if (circle && (t.has("times") || t.has("offsets"))) {
      t.fail(t.has("times") ? "times" : "offsets",
             fmt::format("{} gives both keyframes and a circle; expected times and offsets, or "
                         "centre, axis and period",
                         t.display_name()));
    }
    if (circle) {
      path.centre = t.required_vec3("centre", "m");
      const Vec3 axis = t.vec3("axis", "", Vec3::UnitZ());
      if (axis == Vec3::Zero()) {
        t.fail("axis", fmt::format("'axis' in {} is (0, 0, 0); expected a direction [x, y, z], "
                                   "not zero",
                                   t.display_name()));
      }
      path.axis = unit_direction(axis);
      path.period = t.required_number("period", Range::positive("s"));
    } else {
      path.offsets = read_keyframes(t, "times", "offsets", "m");
      if (path.offsets.empty()) {
        t.fail("pins", fmt::format("{} has no path; expected times and offsets (keyframes), or "
                                   "centre, axis and period (a circle)",
                                   t.display_name()));
      }
    }
    check_path_within_guard(t, scene, path);
    for (Index i : pins)
      on_path[static_cast<size_t>(i)] = true;
    scene.pin_paths.push_back(std::move(path));
  }
}

// Total mass from `mass` [kg] or from `density` [kg/m^2] times `area` [m^2]: exactly one of the
// two keys. The total is shared by `count` particles, each of which must keep a mass (by area:
// the least share is 1/count of it).
double read_mass_or_density(SceneTable& t, double area, Index count, bool by_area) {
  if (t.has("mass") && t.has("density")) {
    t.fail("density", fmt::format("{} gives both mass and density; expected one of the two",
                                  t.display_name()));
  }
  double mass = 0.0;
  if (t.has("density")) {
    const double rho = t.number("density", Range::positive("kg/m^2"), 0.0);
    mass = rho * area;
    if (!std::isfinite(mass)) {
      t.fail("density",
             fmt::format("density = {} kg/m^2 over an area of {:.3g} m^2 is a mass of {} "
                         "kg; expected a finite mass",
                         rho, area, mass));
    }
  } else {
    mass = t.required_number("mass", Range::positive("kg"));
  }
  check_particle_mass(
      t, t.has("density") ? "density" : "mass", mass / static_cast<double>(count),
      by_area ? fmt::format("a corner's share of the cloth's mass of {} kg by "
                            "area, 1/{} of it,",
                            mass, count)
              : fmt::format("the cloth's mass of {} kg shared by {} particles", mass, count));
  return mass;
}

// [rope]: a chain of particles from start to end (lesson 02).
void read_rope(SceneTable& t, Scene& scene) {
  RopeSpec spec;
  spec.start = t.required_vec3("start", "m");
  spec.end = t.required_vec3("end", "m");
  spec.particles = t.required_integer("particles", 2, 1000000);
  spec.mass = t.required_number("mass", Range::positive("kg"));
  check_particle_mass(
      t, "mass", spec.mass / static_cast<double>(spec.particles),
      fmt::format("the rope's mass of {} kg shared by {} particles", spec.mass, spec.particles));
  if (spec.start == spec.end) {
    t.fail("end", "the rope's start and end are the same point; expected a rope of some length");
  }
  Particles& p = scene.world.particles;
  const Rope rope = add_rope(p, spec);
  // The rope lies between its two ends.
  check_within_guard(t, "start", scene, rope.first, "the rope's first particle");
  check_within_guard(t, "end", scene, rope.first + rope.count - 1, "the rope's last particle");
  read_body_motion(t, scene, rope.first, rope.count, "the rope's");
  const auto named = [&](std::string_view name, std::vector<Index>& out) {
    if (name == "first" || name == "both") out.push_back(0);
    if (name == "last" || name == "both") out.push_back(rope.count - 1);
    return name == "first" || name == "last" || name == "both" || name == "none";
  };
  for (Index i : read_pins(t, scene, rope.count, named, "first, last, both, none"))
    pin(p, rope.first + i);
  read_pin_paths(t, scene, rope.first, rope.count, named, "first, last, both, none");
  scene.rope = rope;
}

// The most particles a [cloth] may have, as many as a [rope] (a 1000 x 1000 grid): the 4096 x 4096
// that rows and cols alone allow would need gigabytes before its first step.
constexpr Index kMaxClothParticles = 1000000;

// [cloth]: a rectangular grid of particles (lesson 02).
void read_cloth(SceneTable& t, Scene& scene) {
  ClothSpec spec;
  spec.rows = t.required_integer("rows", 2, 4096);
  spec.cols = t.required_integer("cols", 2, 4096);
  if (spec.rows * spec.cols > kMaxClothParticles) {
    t.fail("cols", fmt::format("[cloth] of {} x {} is {} particles; expected at most {} (rows x "
                               "cols)",
                               spec.rows, spec.cols, spec.rows * spec.cols, kMaxClothParticles));
  }
  spec.spacing = t.required_number("spacing", Range::positive("m"));
  spec.origin = t.vec3("origin", "m", Vec3::Zero());
  spec.horizontal = t.choice("plane", {"vertical", "horizontal"}, "vertical") == "horizontal";
  const double area = static_cast<double>(spec.rows - 1) * static_cast<double>(spec.cols - 1) *
                      spec.spacing * spec.spacing;
  spec.mass_by_area = t.choice("mass_by", {"particle", "area"}, "particle") == "area";
  // By area, a corner of the grid's diagonal gets a third of one triangle's mass: one in six
  // cells' worth, the least of any particle.
  const Index shares =
      spec.mass_by_area ? 6 * (spec.rows - 1) * (spec.cols - 1) : spec.rows * spec.cols;
  spec.mass = read_mass_or_density(t, area, shares, spec.mass_by_area);
  Particles& p = scene.world.particles;
  const ClothGrid grid = add_cloth(p, spec);
  // The grid lies between its first particle, at the origin, and its last.
  check_within_guard(t, "origin", scene, grid.first, "the cloth's first particle");
  check_within_guard(t, "spacing", scene, grid.first + grid.size() - 1,
                     "the cloth's last particle");
  read_body_motion(t, scene, grid.first, grid.size(), "the cloth's");
  const auto named = [&](std::string_view name, std::vector<Index>& out) {
    return named_pins(grid, name, out);
  };
  for (Index i :
       read_pins(t, scene, grid.size(), named, "top-corners, corners, top-edge, left-edge, none")) {
    pin(p, grid.first + i);
  }
  read_pin_paths(t, scene, grid.first, grid.size(), named,
                 "top-corners, corners, top-edge, left-edge, none");
  scene.cloth = grid;
  scene.world.triangles = grid_triangles(grid);
}

// [solid]: a box-shaped lattice of particles, a soft solid (lesson 09).
void read_solid(SceneTable& t, Scene& scene) {
  SolidSpec spec;
  if (!t.has("particles")) {
    t.fail("particles",
           "[solid] has no 'particles'; expected particles = [nx, ny, nz], whole "
           "numbers from 2 to 1000 (particles along x, y and z)");
  }
  const std::vector<long> n = t.integer_list("particles", 2, 1000, "particle count");
  if (n.size() != 3) {
    t.fail("particles", fmt::format("'particles' in [solid] has {} elements; expected [nx, ny, "
                                    "nz], three whole numbers from 2 to 1000",
                                    n.size()));
  }
  spec.nx = n[0], spec.ny = n[1], spec.nz = n[2];
  if (spec.nx * spec.ny * spec.nz > kMaxClothParticles) {
    t.fail("particles",
           fmt::format("[solid] of {} x {} x {} is {} particles; expected at most {} "
                       "(nx ny nz)",
                       spec.nx, spec.ny, spec.nz, spec.nx * spec.ny * spec.nz, kMaxClothParticles));
  }
  spec.size = t.required_vec3("size", "m");
  if (!(spec.size.array() > 0.0).all()) {
    t.fail("size", fmt::format("'size' in [solid] is ({}, {}, {}) m; expected three edge lengths "
                               "> 0 [m]",
                               spec.size.x(), spec.size.y(), spec.size.z()));
  }
  spec.corner = t.vec3("corner", "m", Vec3::Zero());
  spec.mass = t.required_number("mass", Range::positive("kg"));
  const Index count = spec.nx * spec.ny * spec.nz;
  check_particle_mass(
      t, "mass", spec.mass / static_cast<double>(count),
      fmt::format("the solid's mass of {} kg shared by {} particles", spec.mass, count));
  Particles& p = scene.world.particles;
  const SolidLattice lattice = add_solid(p, spec);
  // The box lies between its lowest corner and the opposite one.
  check_within_guard(t, "corner", scene, lattice.first, "the solid's first particle");
  check_within_guard(t, "size", scene, lattice.first + lattice.size() - 1,
                     "the solid's last particle");
  read_body_motion(t, scene, lattice.first, lattice.size(), "the solid's");
  const auto named = [&](std::string_view name, std::vector<Index>& out) {
    return named_solid_pins(lattice, name, out);
  };
  for (Index i : read_pins(t, scene, lattice.size(), named, "top-face, bottom-face, none"))
    pin(p, lattice.first + i);
  read_pin_paths(t, scene, lattice.first, lattice.size(), named, "top-face, bottom-face, none");
  scene.solid = lattice;
  // Its outside, for the viewer and mesh files, after any cloth's triangles.
  const std::vector<Triangle> surface = solid_surface_triangles(lattice);
  scene.world.triangles.insert(scene.world.triangles.end(), surface.begin(), surface.end());
}

// The "springs" effect: structural, shear and one-by-one springs make one effect, first in the
// list, so that reports read in the lessons' order: springs, bending, gravity, ... It is made by
// the first table that adds a spring ([[spring]] or [springs], which always adds some), and those
// tables add to it directly; the post-step effects that change these springs are given it when
// they are made.
SpringDampers* find_springs_effect(Scene& scene) {
  auto& effects = scene.world.force_effects;
  if (effects.empty() || effects.front()->name() != "springs") return nullptr;
  return static_cast<SpringDampers*>(effects.front().get());
}

bool has_springs(Scene& scene) {
  const SpringDampers* effect = find_springs_effect(scene);
  return effect && effect->springs().size() > 0;
}

SpringDampers& springs_effect(Scene& scene) {
  if (SpringDampers* effect = find_springs_effect(scene)) return *effect;
  auto& effects = scene.world.force_effects;
  effects.insert(effects.begin(), std::make_unique<SpringDampers>("springs", SpringSet{}));
  return static_cast<SpringDampers&>(*effects.front());
}

// [[spring]]: one spring-damper between two particles given by index (lesson 02).
void read_spring(SceneTable& t, Scene& scene) {
  const Particles& p = scene.world.particles;
  if (p.size() < 2)
    t.fail("i", "a [[spring]] needs two particles; expected [[particle]] tables first");
  const long last = static_cast<long>(p.size()) - 1;
  const Index i = t.required_integer("i", 0, last);
  const Index j = t.required_integer("j", 0, last);
  if (i == j)
    t.fail("j", fmt::format("the spring joins particle {} to itself; expected i != j", i));
  const double ks = t.required_number("ks", Range::non_negative("N/m"));
  const double kd = t.number("kd", Range::non_negative("N s/m"), 0.0);
  SpringSet& springs = springs_effect(scene).springs();
  // Without l0 the spring is at rest as the particles stand: its rest length is their distance.
  if (t.has("l0"))
    springs.add(i, j, ks, kd, t.required_number("l0", Range::non_negative("m")));
  else
    springs.add_at_rest(i, j, ks, kd, p.x);
  // The strain (l - l0) / l0 divides by l0: a spring of no rest length has none, and its force
  // ks l pulls its ends onto each other.
  if (springs.l0(springs.size() - 1) == 0.0) {
    const std::string what =
        t.has("l0") ? fmt::format("{} has l0 = 0", t.display_name())
                    : fmt::format(
                          "{} joins particles {} and {}, which start at the same "
                          "position, so its rest length (the distance at the start) is 0",
                          t.display_name(), i, j);
    t.warn(scene, "l0",
           fmt::format("{}: with no rest length its strain (l - l0) / l0 is undefined and it pulls "
                       "its ends together until they meet; give l0 > 0 [m]{}",
                       what,
                       t.has("l0") ? " (or leave l0 out: the distance at the start)"
                                   : " or move one of the particles"));
  }
}

// Warns at 'ks' of [springs] or [bending] when springs `from` on include some of rest length 0:
// their ends start at one point, where the body's spacing is too small to tell them apart
// (1 + 1e-300 is 1).
void warn_zero_rest_lengths(SceneTable& t, Scene& scene, const SpringSet& springs, size_t from) {
  size_t zero = 0, first = 0;
  for (size_t k = from; k < springs.size(); ++k) {
    if (springs.l0(k) == 0.0 && zero++ == 0) first = k;
  }
  if (zero == 0) return;
  t.warn(scene, "ks",
         fmt::format("{} makes {} spring{} of rest length 0, the first from particle {} to {}: "
                     "their ends start at the same position, so with no rest length their strain "
                     "(l - l0) / l0 is undefined and they pull their ends together until they "
                     "meet; give the body a spacing (or size) large enough to tell its particles "
                     "apart where it is",
                     t.display_name(), zero, zero == 1 ? "" : "s", springs.i(first),
                     springs.j(first)));
}

// [springs]: structural and shear springs of the cloth, the rope's springs (lesson 02), the
// solid's edges and diagonals (lesson 09).
void read_springs(SceneTable& t, Scene& scene) {
  if (!scene.cloth && !scene.rope && !scene.solid) {
    t.fail("ks",
           "[springs] has nothing to connect; expected a [cloth], a [rope] or a [solid] (springs "
           "between single particles are [[spring]] tables)");
  }
  const double ks = t.required_number("ks", Range::non_negative("N/m"));
  const double kd = t.number("kd", Range::non_negative("N s/m"), 0.0);
  const double shear_ks = t.number("shear_ks", Range::non_negative("N/m"), ks);
  const double shear_kd = t.number("shear_kd", Range::non_negative("N s/m"), kd);
  const Matrix3X& x = scene.world.particles.x;
  SpringSet& springs = springs_effect(scene).springs();
  const size_t from = springs.size();  // after the [[spring]] tables' springs
  if (scene.rope)
    add_spring_family(springs, rope_pairs(scene.rope->count), scene.rope->first, ks, kd, x);
  if (scene.cloth) {
    const ClothGrid& g = *scene.cloth;
    add_spring_family(springs, structural_pairs(g.rows, g.cols), g.first, ks, kd, x);
    add_spring_family(springs, shear_pairs(g.rows, g.cols), g.first, shear_ks, shear_kd, x);
  }
  if (scene.solid) {
    // The cell's edges take ks and kd; both kinds of diagonal resist shear, and take the shear
    // constants, as the cloth's diagonals do.
    const SolidLattice& g = *scene.solid;
    add_spring_family(springs, solid_structural_pairs(g.nx, g.ny, g.nz), g.first, ks, kd, x);
    add_spring_family(springs, solid_face_diagonal_pairs(g.nx, g.ny, g.nz), g.first, shear_ks,
                      shear_kd, x);
    add_spring_family(springs, solid_body_diagonal_pairs(g.nx, g.ny, g.nz), g.first, shear_ks,
                      shear_kd, x);
  }
  warn_zero_rest_lengths(t, scene, springs, from);
}

// [bending]: flexion springs two apart, with their own constants (lesson 04).
void read_bending(SceneTable& t, Scene& scene) {
  if (!scene.cloth && !scene.rope) {
    t.fail("ks", "[bending] has nothing to bend; expected a [cloth] or a [rope]");
  }
  const double ks = t.required_number("ks", Range::non_negative("N/m"));
  const double kd = t.number("kd", Range::non_negative("N s/m"), 0.0);
  const Matrix3X& x = scene.world.particles.x;
  // The cloth's bending layer (exercise ex04.1 picks its pairs), then the rope's, if any.
  SpringSet bending = scene.cloth ? bending_springs(*scene.cloth, ks, kd, x) : SpringSet{};
  if (scene.rope) {
    add_spring_family(bending, rope_bending_pairs(scene.rope->count), scene.rope->first, ks, kd, x);
  }
  warn_zero_rest_lengths(t, scene, bending, 0);
  scene.world.force_effects.push_back(
      std::make_unique<SpringDampers>("bending", std::move(bending)));
}

// [damping]: a damper from every particle to the world, f = -rate m v (lesson 02).
void read_damping(SceneTable& t, Scene& scene) {
  const double rate = t.required_number("rate", Range::non_negative("1/s"));
  scene.world.force_effects.push_back(std::make_unique<Damping>(rate));
}

// The wind of [aerodynamics] or [drag] (wind.hpp): steady (`wind`) or keyframed (`wind_times`,
// `wind_values`), with gusts (`gust`, `gust_period`) or not.
Wind read_wind(SceneTable& t, const Scene& scene) {
  Wind wind;
  if (t.has("wind") && t.has("wind_values")) {
    t.fail("wind_values", fmt::format("{} gives both wind and wind_values; expected a steady wind "
                                      "or winds at times (wind_times, wind_values)",
                                      t.display_name()));
  }
  wind.steady = t.vec3("wind", "m/s", Vec3::Zero());
  wind.table = read_keyframes(t, "wind_times", "wind_values", "m/s");
  if (t.has("gust") != t.has("gust_period")) {
    t.fail(t.has("gust") ? "gust" : "gust_period",
           fmt::format("{} has '{}' without '{}'; expected both: gust = [x, y, z] [m/s], the "
                       "amplitude, and gust_period [s]",
                       t.display_name(), t.has("gust") ? "gust" : "gust_period",
                       t.has("gust") ? "gust_period" : "gust"));
  }
  wind.gust = t.vec3("gust", "m/s", Vec3::Zero());
  wind.gust_period = t.number("gust_period", Range::positive("s"), 0.0);
  // The air drags what it blows on towards its own speed; the guard stops any particle faster
  // than max_speed. A wind beyond that bound (where a square of its speed may not even be a
  // number) is refused here, as a pin path beyond the bounds is.
  const double bound = scene.world.guard.max_speed;
  if (!(wind.top_speed() <= bound)) {
    Wind calm = wind;
    calm.gust_period = 0.0;
    const char* key =
        calm.top_speed() > bound ? (wind.table.empty() ? "wind" : "wind_values") : "gust";
    t.fail(key, fmt::format("{}'s wind reaches {:g} m/s, beyond the guard's max_speed = {:g} "
                            "m/s, the fastest a particle may move; expected a wind within {:g} "
                            "m/s (a larger max_speed in [guard] allows more)",
                            t.display_name(), wind.top_speed(), bound, bound));
  }
  return wind;
}

// [aerodynamics]: air on the cloth's triangles (lesson 03).
void read_aerodynamics(SceneTable& t, Scene& scene) {
  if (!scene.cloth) {
    t.fail("rho", "[aerodynamics] acts on a cloth's triangles; expected a [cloth] table");
  }
  const double rho = t.number("rho", Range::non_negative("kg/m^3"), kAirDensity);
  const double cd = t.number("cd", Range::non_negative(""), 1.0);
  const Wind wind = read_wind(t, scene);
  auto aerodynamics = std::make_unique<Aerodynamics>(scene.world.triangles, rho, cd, wind.at(0.0));
  if (wind.changes()) aerodynamics->set_gusts(wind);
  scene.world.force_effects.push_back(std::move(aerodynamics));
}

// [drag]: fluid drag on every particle (lesson 03).
void read_drag(SceneTable& t, Scene& scene) {
  const double rho = t.number("rho", Range::non_negative("kg/m^3"), kAirDensity);
  const double cd = t.number("cd", Range::non_negative(""), 0.47);  // a sphere's
  const double area = t.required_number("area", Range::positive("m^2"));
  const Wind wind = read_wind(t, scene);
  auto drag = std::make_unique<FluidDrag>(rho, cd, area, wind.at(0.0));
  if (wind.changes()) drag->set_gusts(wind);
  scene.world.force_effects.push_back(std::move(drag));
}

// [buoyancy]: a fluid below y = surface lifts the particles in it (lesson 03).
void read_buoyancy(SceneTable& t, Scene& scene) {
  const double rho = t.number("rho", Range::positive("kg/m^3"), 1000.0);  // water
  const double volume = t.required_number("volume", Range::positive("m^3"));
  const double surface = t.number("surface", Range::any("m"), 0.0);
  // Against the scene's gravity when it has one ([gravity] is read first), else against -y; `g`
  // sets the strength alone.
  Vec3 down(0.0, -1.0, 0.0);
  double strength = 9.8;
  for (const auto& effect : scene.world.force_effects) {
    if (const auto* gravity = dynamic_cast<const UniformGravity*>(effect.get())) {
      if (gravity->g() == Vec3::Zero()) continue;
      // Scaled first: g = [0, 1e-170, 0] points up, though |g|^2 underflows to 0.
      const Vec3 along = unit_direction(gravity->g());
      if (const double norm = gravity->g().dot(along); std::isfinite(norm)) {
        down = along;
        strength = norm;
      }
    }
  }
  const double g = t.number("g", Range::positive("m/s^2"), strength);
  scene.world.force_effects.push_back(std::make_unique<Buoyancy>(rho, volume, surface, g * down));
}

// [gravity]: uniform gravity, f = m g (lesson 01).
void read_gravity(SceneTable& t, Scene& scene) {
  const Vec3 g = t.vec3("g", "m/s^2", Vec3(0.0, -9.8, 0.0));
  scene.world.force_effects.push_back(std::make_unique<UniformGravity>(g));
}

// [gravitation]: Newton's gravitation between every pair of particles (lesson 01).
void read_gravitation(SceneTable& t, Scene& scene) {
  const double G = t.number("G", Range::positive("N m^2/kg^2"), kGravitationalConstant);
  scene.world.force_effects.push_back(std::make_unique<Gravitation>(G));
}

// The contact constants shared by [ground] and [sphere] (lesson 05).
ContactMaterial read_material(SceneTable& t) {
  ContactMaterial m;
  m.e = t.number("e", Range{0.0, 1.0, false, ""}, m.e);
  m.mu_s = t.number("mu_s", Range::non_negative(""), m.mu_s);
  m.mu_d = t.number("mu_d", Range::non_negative(""), std::min(m.mu_d, m.mu_s));
  m.rest_speed = t.number("rest_speed", Range::non_negative("m/s"), m.rest_speed);
  if (m.mu_d > m.mu_s) {
    t.fail("mu_d", fmt::format("mu_d = {} is larger than mu_s = {}; expected mu_d <= mu_s (sliding "
                               "never grips harder than sticking)",
                               m.mu_d, m.mu_s));
  }
  return m;
}

// [strain_limit]: springs shortened back to a largest strain after each step (lesson 09).
void read_strain_limit(SceneTable& t, Scene& scene) {
  if (!has_springs(scene)) {
    t.fail("max_strain",
           "[strain_limit] has no springs to limit; expected [springs] or [[spring]] tables");
  }
  StrainLimits limits;
  limits.max_strain = t.required_number("max_strain", Range::non_negative(""));
  limits.max_compression =
      t.number("max_compression", Range{0.0, 1.0, false, ""}, limits.max_compression);
  const long iterations = t.integer("iterations", 1, 10000, 10);
  scene.world.post_step_effects.push_back(std::make_unique<StrainLimiting>(
      springs_effect(scene), limits, static_cast<int>(iterations)));
}

// The most cells of edge `thickness` along each axis of the guard's box, |x| <= max_position:
// cell coordinates up to 1e15 fit easily in 64-bit integers (about 9.2e18).
constexpr double kMaxCellsAcross = 1e15;

// [self_collision]: particles kept `thickness` apart from each other (lesson 10).
void read_self_collision(SceneTable& t, Scene& scene) {
  SelfContact c;
  c.thickness = t.required_number("thickness", Range::positive("m"));
  const double bound = scene.world.guard.max_position;
  if (bound / c.thickness > kMaxCellsAcross) {
    t.fail("thickness",
           fmt::format("thickness = {} m makes {:.3g} cells across the guard's max_position = {} "
                       "m; expected thickness >= {:.3g} m (or a smaller max_position in [guard])",
                       c.thickness, bound / c.thickness, bound, bound / kMaxCellsAcross));
  }
  c.e = t.number("e", Range{0.0, 1.0, false, ""}, c.e);
  c.mu_s = t.number("mu_s", Range::non_negative(""), c.mu_s);
  c.mu_d = t.number("mu_d", Range::non_negative(""), std::min(c.mu_d, c.mu_s));
  if (c.mu_d > c.mu_s) {
    t.fail("mu_d", fmt::format("mu_d = {} is larger than mu_s = {}; expected mu_d <= mu_s (sliding "
                               "never grips harder than sticking)",
                               c.mu_d, c.mu_s));
  }
  const long iterations = t.integer("iterations", 1, 1000, 4);
  scene.world.post_step_effects.push_back(
      std::make_unique<SelfCollision>(c, static_cast<int>(iterations), scene.world.particles.x));
}

// [ground]: the plane y = y0, solid below (lesson 05).
void read_ground(SceneTable& t, Scene& scene) {
  const double y0 = t.number("y", Range::any("m"), 0.0);
  const bool simple = t.choice("model", {"coulomb", "simple"}, "coulomb") == "simple";
  const double friction = t.number("friction", Range{0.0, 1.0, false, ""}, 0.0);
  if (!simple && t.has("friction")) {
    t.fail("friction",
           "'friction' belongs to model = \"simple\"; expected mu_s and mu_d for the "
           "Coulomb model");
  }
  if (simple) {
    for (std::string_view key : {"mu_s", "mu_d", "rest_speed"}) {
      if (t.has(key)) {
        t.fail(key, fmt::format("'{}' belongs to the Coulomb model; expected only e and friction "
                                "with model = \"simple\"",
                                key));
      }
    }
  }
  const ContactMaterial m = read_material(t);
  scene.world.post_step_effects.push_back(std::make_unique<Ground>(
      y0, m, simple ? Ground::Model::simple : Ground::Model::coulomb, friction));
}

// [sphere]: a solid ball (lesson 05).
void read_sphere(SceneTable& t, Scene& scene) {
  const Vec3 centre = t.required_vec3("centre", "m");
  const double radius = t.required_number("radius", Range::positive("m"));
  scene.world.post_step_effects.push_back(
      std::make_unique<Sphere>(centre, radius, read_material(t)));
}

// [[plane]]: a plane through a point with an outward normal, solid on the other side: a ramp
// (lesson 05).
void read_plane(SceneTable& t, Scene& scene) {
  const Vec3 point = t.required_vec3("point", "m");
  const Vec3 normal = t.required_vec3("normal", "");
  if (normal.cwiseAbs().maxCoeff() == 0.0) {
    t.fail("normal",
           "normal = [0, 0, 0] has no direction; expected the plane's outward normal, "
           "e.g. [0, 1, 0] for a floor");
  }
  scene.world.post_step_effects.push_back(std::make_unique<Plane>(point, normal, read_material(t)));
}

// [plasticity]: springs whose rest length yields past an elastic limit (lesson 06).
void read_plasticity(SceneTable& t, Scene& scene) {
  if (!has_springs(scene)) {
    t.fail("yield_strain",
           "[plasticity] has no springs to deform; expected [springs] or "
           "[[spring]] tables");
  }
  PlasticLimits limits;
  limits.yield_strain = t.required_number("yield_strain", Range{0.0, 0.99, true, ""});
  limits.flow_rate = t.number("flow_rate", Range::positive("1/s"), limits.flow_rate);
  limits.max_strain = t.number("max_strain", Range{0.0, 0.99, false, ""}, limits.max_strain);
  scene.world.post_step_effects.push_back(
      std::make_unique<Plasticity>(springs_effect(scene), limits));
}

// [tearing]: springs that break past a tearing limit, and the triangles they edge (lesson 06).
void read_tearing(SceneTable& t, Scene& scene) {
  if (!has_springs(scene)) {
    t.fail("strain", "[tearing] has no springs to tear; expected [springs] or [[spring]] tables");
  }
  const double strain = t.required_number("strain", Range::positive(""));
  const long max_tears = t.integer("max_per_step", 0, 1000000000, 0);
  // The effects it changes, by type, once: bending springs and the air's triangles, if any.
  SpringDampers* bending = nullptr;
  std::vector<Aerodynamics*> aerodynamics;
  for (auto& effect : scene.world.force_effects) {
    if (effect->name() == "bending") bending = dynamic_cast<SpringDampers*>(effect.get());
    if (auto* aero = dynamic_cast<Aerodynamics*>(effect.get())) aerodynamics.push_back(aero);
  }
  scene.world.post_step_effects.push_back(
      std::make_unique<Tearing>(springs_effect(scene), bending, std::move(aerodynamics), strain,
                                static_cast<size_t>(max_tears)));
}

// [integrator]: the method, the time step and how long to simulate.
void read_integrator(SceneTable& t, Scene& scene) {
  const std::vector<std::string_view> names(method_names().begin(), method_names().end());
  const std::string method = t.choice("method", names, "symplectic-euler");
  scene.world.integrator = make_integrator(method);
  // The substeps and projections of the position-based method, the iterations of the
  // local/global solver and of vertex block descent; the force-based ones have none.
  if (method != "xpbd" && t.has("substeps")) {
    t.fail("substeps", fmt::format("substeps sets the position-based method = \"xpbd\" (lesson "
                                   "12), but method is \"{}\"; expected no substeps here",
                                   method));
  }
  if (method != "xpbd" && method != "local-global" && method != "vbd" && t.has("iterations")) {
    t.fail("iterations",
           fmt::format("iterations sets the iterations of method = \"xpbd\" (lesson 12), "
                       "\"local-global\" (lesson 13) or \"vbd\" (lesson 14), but method is "
                       "\"{}\"; expected no iterations here",
                       method));
  }
  if (auto* xpbd = dynamic_cast<Xpbd*>(scene.world.integrator.get())) {
    xpbd->substeps = static_cast<int>(t.integer("substeps", 1, 100'000, xpbd->substeps));
    xpbd->iterations = static_cast<int>(t.integer("iterations", 1, 10'000, xpbd->iterations));
  }
  if (auto* local_global = dynamic_cast<LocalGlobal*>(scene.world.integrator.get())) {
    local_global->iterations =
        static_cast<int>(t.integer("iterations", 1, 10'000, local_global->iterations));
  }
  if (method != "vbd" && t.has("initial_guess")) {
    t.fail("initial_guess",
           fmt::format("initial_guess sets where the iterations of method = \"vbd\" (lesson 14) "
                       "start, but method is \"{}\"; expected no initial_guess here",
                       method));
  }
  if (auto* vbd = dynamic_cast<Vbd*>(scene.world.integrator.get())) {
    vbd->iterations = static_cast<int>(t.integer("iterations", 1, 10'000, vbd->iterations));
    vbd->initial_guess = t.choice("initial_guess", {"inertia", "adaptive"}, "inertia") == "adaptive"
                             ? VbdInitialGuess::adaptive
                             : VbdInitialGuess::inertia;
  }
  // The linear solver of the implicit method; another method has none to tune.
  for (const char* key : {"tolerance", "max_iterations"}) {
    if (method != "implicit-euler" && t.has(key)) {
      t.fail(key, fmt::format("{} tunes the linear solver of method = \"implicit-euler\", but "
                              "method is \"{}\"; expected no {} here",
                              key, method, key));
    }
  }
  if (auto* implicit = dynamic_cast<ImplicitEuler*>(scene.world.integrator.get())) {
    implicit->tolerance = t.number("tolerance", Range{0.0, 1.0, true, ""}, implicit->tolerance);
    implicit->max_iterations =
        static_cast<int>(t.integer("max_iterations", 1, 1'000'000, implicit->max_iterations));
  }
  scene.dt = t.required_number("dt", Range::positive("s"));
  scene.duration = t.required_number("duration", Range::positive("s"));
  if (scene.dt > scene.duration) {
    t.fail("dt", fmt::format("dt = {} s is longer than duration = {} s; expected dt <= duration",
                             scene.dt, scene.duration));
  }
  // Scene::step_count() rounds duration / dt to a whole number, which must fit in a long.
  if (scene.duration / scene.dt > 1e9) {
    t.fail("dt", fmt::format("dt = {} s over duration = {} s is {:.3g} steps; expected at most "
                             "1e9 steps (a larger dt or a shorter duration)",
                             scene.dt, scene.duration, scene.duration / scene.dt));
  }
}

// [output]: what a run writes.
void read_output(SceneTable& t, Scene& scene) {
  scene.output.fps = t.number("fps", Range::positive("frames/s"), scene.output.fps);
  // A run writes a frame every round(1 / (fps dt)) steps, at least one ([integrator], read
  // before, gives dt): above 1/dt, fps asks for more frames than there are steps. The 1e-9
  // keeps fps = 100 with dt = 0.01, whose product may round a hair above 1, quiet.
  if (scene.output.fps * scene.dt > 1.0 + 1e-9) {
    t.warn(scene, "fps",
           fmt::format("fps = {} frames/s is more than the step rate 1/dt = {:.6g} steps/s: a "
                       "frame is written every step, so the run writes {:.6g} frames per "
                       "simulated second, not {}; take fps <= {:.6g} (or a smaller dt)",
                       scene.output.fps, 1.0 / scene.dt, 1.0 / scene.dt, scene.output.fps,
                       1.0 / scene.dt));
  }
  scene.output.velocities = t.boolean("velocities", scene.output.velocities);
  scene.output.springs = t.boolean("springs", scene.output.springs);
  scene.output.npy = t.choice("format", {"csv", "npy"}, "csv") == "npy";
}

// [guard]: the bounds beyond which a run is stopped as blown up.
void read_guard(SceneTable& t, Scene& scene) {
  Guard& guard = scene.world.guard;
  guard.max_position = t.number("max_position", Range::positive("m"), guard.max_position);
  guard.max_speed = t.number("max_speed", Range::positive("m/s"), guard.max_speed);
  guard.max_energy_growth =
      t.number("max_energy_growth", Range::positive(""), guard.max_energy_growth);
}

// What of `scene` the float room would compute with that a float cannot hold, or "": a number of
// the scene (ks = 1e39 would be inf, and the first step NaN), a particle's 1/m (the move's) or its
// start. A step in float of any of them could only blow up.
std::string beyond_float(const Scene& scene) {
  for (const TunableNumber& number : scene.tunables) {
    if (std::abs(number.value) > kFloatMax)
      return fmt::format("{} = {:g}{}{}", number.path, number.value, number.unit.empty() ? "" : " ",
                         number.unit);
  }
  const Particles& p = scene.world.particles;
  for (Index i = 0; i < p.size(); ++i) {
    if (p.inv_m[i] > kFloatMax)
      return fmt::format("particle {}'s mass, {:g} kg, whose inverse is {:g} 1/kg", i, p.m[i],
                         p.inv_m[i]);
    if (p.x.col(i).cwiseAbs().maxCoeff() > kFloatMax)
      return fmt::format("particle {}'s start, {:g} m from the origin along an axis", i,
                         p.x.col(i).cwiseAbs().maxCoeff());
    if (p.v.col(i).cwiseAbs().maxCoeff() > kFloatMax)
      return fmt::format("particle {}'s start velocity, {:g} m/s along an axis", i,
                         p.v.col(i).cwiseAbs().maxCoeff());
  }
  return "";
}

// [engine]: how the engine runs the scene (the physics does not depend on it).
void read_engine(SceneTable& t, Scene& scene) {
  World& world = scene.world;
  // 0: every core the machine has, as --threads 0.
  const long threads = t.integer("threads", 0, 1024, world.threads);
  world.threads = threads > 0 ? static_cast<int>(threads) : ThreadTeam::hardware_threads();
  if (!t.boolean("fast_path", true)) world.backend.reset();
  // The numbers the engine room computes with (fast/float_room.hpp). Read last of the scene's
  // tables: float covers some methods and effects only, and says so here.
  if (t.choice("precision", {"double", "float"}, "double") == "float") {
    if (const std::string why = fast::use_float(world); !why.empty()) {
      t.fail("precision",
             fmt::format("precision = \"float\": {}; expected precision = \"double\"", why));
    }
    if (const std::string why = beyond_float(scene); !why.empty()) {
      t.fail("precision", fmt::format("precision = \"float\": {}, beyond what a float holds "
                                      "({:g}); expected precision = \"double\"",
                                      why, std::numeric_limits<float>::max()));
    }
  }
}

// The order here is the order of reading: the guard's bounds, which the particles must start
// within, then whatever creates particles, then the effects on them.
constexpr std::array kKinds = {
    SceneTableKind{"guard", false, false, "max_position max_speed max_energy_growth",
                   "[guard] with max_position and max_speed", read_guard},
    SceneTableKind{"particle", true, false, "position velocity mass pinned",
                   "[[particle]] with position, velocity and mass", read_particle},
    SceneTableKind{"rope", false, false, "start end particles mass pins velocity spin pin_path",
                   "[rope] with start, end, particles and mass", read_rope},
    SceneTableKind{
        "cloth", false, false,
        "rows cols spacing origin plane mass density mass_by pins velocity spin pin_path",
        "[cloth] with rows, cols, spacing and mass", read_cloth},
    SceneTableKind{"solid", false, false, "particles size corner mass pins velocity spin pin_path",
                   "[solid] with particles, size and mass", read_solid},
    SceneTableKind{"spring", true, false, "i j ks kd l0", "[[spring]] with i, j and ks",
                   read_spring, "ks kd"},
    SceneTableKind{"springs", false, false, "ks kd shear_ks shear_kd", "[springs] with ks",
                   read_springs, "ks kd shear_ks shear_kd"},
    SceneTableKind{"bending", false, false, "ks kd", "[bending] with ks", read_bending, "ks kd"},
    SceneTableKind{"damping", false, false, "rate", "[damping] with rate", read_damping, "rate"},
    SceneTableKind{"gravity", false, false, "g", "[gravity] with g", read_gravity, "g"},
    SceneTableKind{"gravitation", false, false, "G", "[gravitation] with G", read_gravitation, "G"},
    SceneTableKind{"aerodynamics", false, false,
                   "rho cd wind wind_times wind_values gust gust_period",
                   "[aerodynamics] with rho, cd and wind", read_aerodynamics, "rho cd wind gust"},
    SceneTableKind{"drag", false, false, "rho cd area wind wind_times wind_values gust gust_period",
                   "[drag] with area", read_drag, "rho cd area wind gust"},
    SceneTableKind{"buoyancy", false, false, "rho volume surface g", "[buoyancy] with volume",
                   read_buoyancy, "rho volume surface"},
    // Before the colliders, so that a contact has the last word on where a particle ends up.
    SceneTableKind{"strain_limit", false, false, "max_strain max_compression iterations",
                   "[strain_limit] with max_strain", read_strain_limit,
                   "max_strain max_compression"},
    SceneTableKind{"self_collision", false, false, "thickness e mu_s mu_d iterations",
                   "[self_collision] with thickness", read_self_collision, "thickness e mu_s mu_d"},
    SceneTableKind{"ground", false, false, "y e mu_s mu_d rest_speed model friction",
                   "[ground] with y, e, mu_s and mu_d", read_ground, "y e mu_s mu_d rest_speed"},
    SceneTableKind{"sphere", false, false, "centre radius e mu_s mu_d rest_speed",
                   "[sphere] with centre and radius", read_sphere,
                   "centre radius e mu_s mu_d rest_speed"},
    SceneTableKind{"plane", true, false, "point normal e mu_s mu_d rest_speed",
                   "[[plane]] with point and normal", read_plane, "e mu_s mu_d rest_speed"},
    SceneTableKind{"plasticity", false, false, "yield_strain flow_rate max_strain",
                   "[plasticity] with yield_strain", read_plasticity,
                   "yield_strain flow_rate max_strain"},
    SceneTableKind{"tearing", false, false, "strain max_per_step", "[tearing] with strain",
                   read_tearing, "strain"},
    SceneTableKind{"integrator", false, true,
                   "method dt duration tolerance max_iterations substeps iterations initial_guess",
                   "[integrator] with method, dt [s] and duration [s]", read_integrator},
    SceneTableKind{"output", false, false, "fps velocities springs format", "[output] with fps",
                   read_output},
    SceneTableKind{"engine", false, false, "threads fast_path precision", "[engine] with threads",
                   read_engine},
};

}  // namespace

std::span<const SceneTableKind> scene_table_kinds() {
  return kKinds;
}

const SceneTableKind* find_scene_table(std::string_view name) {
  for (const SceneTableKind& kind : kKinds) {
    if (kind.name == name) return &kind;
  }
  return nullptr;
}

std::string scene_table_names() {
  std::string names = "title";
  for (const SceneTableKind& kind : kKinds) {
    names += ' ';
    names += kind.name;
  }
  return names;
}

void finish_scene(Scene& scene, const std::function<void(const std::string&)>& fail) {
  if (scene.world.particles.size() == 0) {
    fail(
        "the scene has no particles; expected [[particle]] tables, a [rope], a [cloth] or a "
        "[solid]");
  }
  // The pins that move, last: where a path puts a particle is where it is after the step.
  if (!scene.pin_paths.empty()) {
    auto pins = std::make_unique<MovingPins>(std::move(scene.pin_paths));
    pins->place(scene.world.particles, 0.0);
    scene.world.post_step_effects.push_back(std::move(pins));
    scene.pin_paths.clear();
  }
}

}  // namespace clothlab
