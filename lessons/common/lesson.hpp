// lesson.hpp: what every lesson program shares, so that each main.cpp holds only its lesson.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <source_location>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <fmt/format.h>

#include "clothlab/core/not_implemented.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab::lesson {

// The file `name` in the lesson's own folder (its scenes lie next to its main.cpp).
inline std::filesystem::path lesson_file(
    const char* name, std::source_location here = std::source_location::current()) {
  return std::filesystem::path(here.file_name()).parent_path() / name;
}

// The springs of the world's "springs" effect (structural, shear, [[spring]]).
inline SpringSet& springs_of(World& world) {
  SpringDampers* springs = find_spring_effect(world, "springs");
  if (!springs) throw std::runtime_error("the scene has no [springs]");
  return springs->springs();
}

// The largest strain (l - l0) / l0 of the world's "springs" (0 if none is stretched).
inline double largest_strain(World& world) {
  const SpringSet& s = springs_of(world);
  double worst = 0.0;
  for (size_t k = 0; k < s.size(); ++k) {
    const double l = (world.particles.x.col(s.j(k)) - world.particles.x.col(s.i(k))).norm();
    worst = std::max(worst, (l - s.l0(k)) / s.l0(k));
  }
  return worst;
}

// Kinetic plus potential energy [J].
inline double energy(const World& world) {
  return world.kinetic_energy() + world.potential_energy();
}

// Steps the world by dt for `seconds` of simulated time (the nearest whole number of steps).
inline void run_for(World& world, double dt, double seconds) {
  const long steps = std::lround(seconds / dt);
  for (long s = 0; s < steps; ++s)
    world.step(dt);
}

using Clock = std::chrono::steady_clock;

// Wall time since `start` [s].
inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A lesson program's exit status: the codes `clothlab` itself gives (engine/app/exit_codes.hpp),
// so that a script reads both alike (tests/engine/lesson_common.cpp checks they agree).
enum ExitCode : int { kExitOk = 0, kExitFailed = 1, kExitNotDone = 4 };

// Runs the lesson's tables and says what stopped them: an exercise still a stub (exit code 4,
// as `clothlab run` gives), or any other error (1). A body may return an exit code of its own.
template <class Body>
int run(const char* program, Body body) {
  try {
    if constexpr (std::is_void_v<decltype(body())>) {
      body();
    } else {
      return body();
    }
  } catch (const NotImplemented& error) {
    fmt::print(stderr, "{}: {}\n", program, error.what());
    return kExitNotDone;
  } catch (const std::exception& error) {
    fmt::print(stderr, "{}: {}\n", program, error.what());
    return kExitFailed;
  }
  return kExitOk;
}

// x >= 0 with `decimals` decimals, rounded down: a stable limit printed must hold at exactly the
// value printed, so 1.23607 is 1.2360, not 1.2361 (round_down in analysis/stability.hpp does the
// same with significant digits).
inline std::string round_down_to(double x, int decimals) {
  const double unit = std::pow(10.0, -decimals);
  // The factor keeps 0.2 from coming out as 1999.99999 units; the check undoes a step too far.
  double q = std::floor(x / unit * (1.0 + 1e-12));
  for (;;) {
    const std::string text = fmt::format("{:.{}f}", q * unit, decimals);
    if (std::stod(text) <= x) return text;
    q -= 1.0;
  }
}

}  // namespace clothlab::lesson
