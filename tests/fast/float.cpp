// The float room (engine/fast/float_room.hpp): `[engine] precision = "float"` steps in single
// precision, stays within a derived distance of the double run on every lesson scene it covers,
// refuses at load what it does not cover, and keeps the guard and the time-step advisor working.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "analysis/stability.hpp"
#include "clothlab/core/guard.hpp"
#include "fast/engine.hpp"
#include "fast/float_room.hpp"
#include "fast/scalar_kernels.hpp"
#include "fast_util.hpp"
#include "scene/scene.hpp"

using clothlab::Index;
using clothlab::Matrix3X;

namespace {

namespace fs = std::filesystem;

// Every entry of a is a float: rounding it to float and back changes nothing.
bool all_floats(const Matrix3X& a) {
  return (a.array() == a.cast<float>().cast<double>().array()).all();
}

// A hanging cloth with every force the float room covers. (Contacts: the lesson scenes below.)
std::string cloth(const std::string& method = "symplectic-euler", double dt = 0.0005,
                  const std::string& extra = "", const std::string& precision = "float") {
  return test::hanging_cloth(30, 27) + R"(
[integrator]
method = ")" +
         method + "\"\ndt = " + std::to_string(dt) + "\nduration = 1.0\n" + extra +
         "[engine]\nprecision = \"" + precision + "\"\n";
}

clothlab::Scene steps(const std::string& text, int count, int threads = 1) {
  clothlab::Scene scene = clothlab::parse_scene(text, "float.toml");
  scene.world.threads = threads;
  for (int s = 0; s < count; ++s)
    scene.world.step(scene.dt);
  return scene;
}

// The SceneError `text` raises, or "" when it loads.
std::string load_error(const std::string& text) {
  try {
    clothlab::parse_scene(text, "float.toml");
  } catch (const clothlab::SceneError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("float: a float run steps in single precision and a double run does not") {
  // Every number the float room writes back is a float; a double run's positions are not (a
  // float path that quietly ran in double fails here).
  const clothlab::Scene single = steps(cloth(), 20);
  const clothlab::Scene full = steps(cloth("symplectic-euler", 0.0005, "", "double"), 20);
  CHECK(single.world.backend_evaluations == 20);
  CHECK(all_floats(single.world.particles.x));
  CHECK(all_floats(single.world.particles.v));
  CHECK(all_floats(single.world.particles.f));
  CHECK_FALSE(all_floats(full.world.particles.x));
  // Close, not the same: 20 steps of rounding to float.
  const double gap = (single.world.particles.x - full.world.particles.x).cwiseAbs().maxCoeff();
  CHECK(gap > 0.0);
  CHECK(gap < 1e-5);
}

TEST_CASE("float: the same bits on 1 to 4 threads, however the particles are split") {
  // Each particle gets the same float operations in the same order on any number of threads.
  const Matrix3X one = steps(cloth(), 30, 1).world.particles.x;
  for (int threads = 2; threads <= 4; ++threads) {
    CAPTURE(threads);
    const clothlab::Scene scene = steps(cloth(), 30, threads);
    CHECK((scene.world.particles.x.array() == one.array()).all());
    // And on any split of the particles between the threads (a step's pass moves it toward
    // the busier thread's side): a new one each step, pieces empty and of any length.
    clothlab::Scene split = clothlab::parse_scene(cloth(), "float.toml");
    split.world.threads = threads;
    const clothlab::Index n = split.world.particles.size();
    std::mt19937 random(11);
    std::uniform_int_distribution<clothlab::Index> anywhere(0, n);
    for (int s = 0; s < 30; ++s) {
      std::vector<clothlab::Index> bounds{0, n};
      for (int t = 1; t < threads; ++t)
        bounds.insert(bounds.end() - 1, s % 7 == 0 ? clothlab::Index{0} : anywhere(random));
      std::sort(bounds.begin(), bounds.end());
      split.world.set_particle_bounds(bounds);
      split.world.step(split.dt);
    }
    CHECK((split.world.particles.x.array() == one.array()).all());
  }
}

TEST_CASE("float: a step wakes the threads once") {
  // The copy into the float copies and the pass that sums and moves are one job of the threads,
  // with a barrier inside it, as on the fast path; the guard's energy check (every 32 steps, in
  // double) wakes them once more, for the springs' energies.
  for (int threads : {2, 4}) {
    CAPTURE(threads);
    clothlab::Scene scene = steps(cloth(), 1, threads);
    const long checks = test::energy_check_wakes(scene.world, scene.world.steps, 40);
    const long before = scene.world.thread_wakes();
    for (int s = 0; s < 40; ++s)
      scene.world.step(scene.dt);
    CHECK(scene.world.thread_wakes() - before == 40 + checks);
  }
}

TEST_CASE("float: the float room reads the rest lengths and constants the set has now") {
  // The float room rounds the springs' constants to float once, when the set changes. A rest
  // length set between two steps (set_l0, as a program or a tool may) and a stiffness set on a
  // whole family (set_ks) must reach its next step: the run is the same, bit for bit, as one
  // whose engine room is made anew at that step and so rounds the new constants from scratch.
  // (The cloth's row springs are in a stencil, so its rows of rest lengths are tested as well.)
  const auto edited = [](bool fresh_room, const std::function<void(clothlab::SpringSet&)>& edit) {
    clothlab::Scene scene = steps(cloth(), 10);
    clothlab::SpringSet* set = nullptr;
    for (auto& effect : scene.world.force_effects) {
      if (auto* springs = dynamic_cast<clothlab::SpringDampers*>(effect.get()); springs && !set)
        set = &springs->springs();
    }
    REQUIRE(set != nullptr);
    edit(*set);
    if (fresh_room) {
      scene.world.backend = clothlab::fast::make_fast_engine();
      REQUIRE(clothlab::fast::use_float(scene.world).empty());
    }
    for (int s = 0; s < 10; ++s)
      scene.world.step(scene.dt);
    return Matrix3X(scene.world.particles.x);
  };
  const Matrix3X plain = edited(false, [](clothlab::SpringSet&) {});
  const std::vector<std::pair<const char*, std::function<void(clothlab::SpringSet&)>>> edits = {
      {"a rest length", [](clothlab::SpringSet& s) { s.set_l0(40, 1.5 * s.l0(40)); }},
      {"every stiffness", [](clothlab::SpringSet& s) {
         for (size_t k = 0; k < s.size(); ++k)
           s.set_ks(k, 2.0 * s.ks(k));
       }}};
  for (const auto& [name, edit] : edits) {
    const std::string what = name;
    CAPTURE(what);
    const Matrix3X kept = edited(false, edit);
    const Matrix3X fresh = edited(true, edit);
    CHECK((kept.array() != plain.array()).any());  // the edit changes the motion
    CHECK((kept.array() == fresh.array()).all());  // and the float room saw it at once
  }
}

TEST_CASE("float: explicit Euler moves with the old velocity") {
  // One step from rest under gravity alone: symplectic Euler moves the free particles by
  // g dt^2, explicit Euler not at all (it moves with v = 0). A float room that took the wrong
  // kernel fails here.
  const std::string one = R"([[particle]]
position = [0.0, 1.0, 0.0]
velocity = [0.0, 0.0, 0.0]
mass = 1.0
[gravity]
[integrator]
method = "METHOD"
dt = 0.01
duration = 1.0
[engine]
precision = "float"
)";
  for (const std::string method : {"symplectic-euler", "explicit-euler"}) {
    std::string text = one;
    text.replace(text.find("METHOD"), 6, method);
    const clothlab::Scene scene = steps(text, 1);
    const double y = scene.world.particles.x(1, 0);
    // float(1 - 9.8e-4): g dt^2 = 9.8e-4 m, rounded as the float room rounds it.
    const double expected =
        method == "explicit-euler" ? 1.0 : static_cast<double>(1.0f + (-9.8f * 0.01f) * 0.01f);
    CAPTURE(method);
    CHECK(y == expected);
    CHECK(scene.world.particles.v(1, 0) == static_cast<double>(-9.8f * 0.01f));
  }
}

TEST_CASE("float: the float spring kernel is the lecture's spring-damper") {
  // spring_force (scalar_kernels.hpp) in double against the exercise's kernel on random
  // springs: the same formula, so within a few roundings of each other; and no force between
  // coincident ends, as the reference.
  using clothlab::Vec3;
  const Vec3 r1(0.1, -0.2, 0.3), r2(0.4, 0.5, -0.1), v1(1.0, 0.2, -0.3), v2(-0.5, 0.1, 0.7);
  const Vec3 a = clothlab::fast::spring_force<double>(r1, r2, v1, v2, 50.0, 0.3, 0.6);
  const Vec3 b = clothlab::spring_damper_force(r1, r2, v1, v2, 50.0, 0.3, 0.6);
  CHECK((a - b).norm() <= 1e-14 * b.norm());
  const clothlab::fast::Vec3f f = clothlab::fast::spring_force<float>(
      r1.cast<float>(), r2.cast<float>(), v1.cast<float>(), v2.cast<float>(), 50.0f, 0.3f, 0.6f);
  CHECK((f.cast<double>() - b).norm() <= 1e-6 * b.norm());
  CHECK(clothlab::fast::spring_force<float>(r1.cast<float>(), r1.cast<float>(), v1.cast<float>(),
                                            v2.cast<float>(), 50.0f, 0.3f, 0.6f)
            .isZero());
}

TEST_CASE("float: the float aerodynamic kernel is the lecture's air on a triangle") {
  // aerodynamic_force_of (scalar_kernels.hpp) in double against the exercise's kernel: the same
  // formula, so within a few roundings; in float within float's; zero for a triangle of no area
  // or one moving with the air, as the reference.
  using clothlab::Vec3;
  using clothlab::fast::aerodynamic_force_of;
  using clothlab::fast::Vec3f;
  const Vec3 r1(0.1, -0.2, 0.3), r2(0.4, 0.5, -0.1), r3(-0.3, 0.2, 0.6);
  const Vec3 v1(1.0, 0.2, -0.3), v2(-0.5, 0.1, 0.7), v3(0.3, -0.4, 0.2), air(4.0, 0.5, -1.0);
  const Vec3 b = clothlab::aerodynamic_force(r1, r2, r3, v1, v2, v3, air, 1.225, 1.1);
  REQUIRE(b.norm() > 0.1);
  const Vec3 a = aerodynamic_force_of<double>(r1, r2, r3, v1, v2, v3, air, 1.225, 1.1);
  CHECK((a - b).norm() <= 1e-14 * b.norm());
  const Vec3f f = aerodynamic_force_of<float>(r1.cast<float>(), r2.cast<float>(), r3.cast<float>(),
                                              v1.cast<float>(), v2.cast<float>(), v3.cast<float>(),
                                              air.cast<float>(), 1.225f, 1.1f);
  CHECK((f.cast<double>() - b).norm() <= 1e-6 * b.norm());
  // The force does not depend on the winding, and a flat triangle or still air gives none.
  const Vec3f flipped = aerodynamic_force_of<float>(
      r1.cast<float>(), r3.cast<float>(), r2.cast<float>(), v1.cast<float>(), v3.cast<float>(),
      v2.cast<float>(), air.cast<float>(), 1.225f, 1.1f);
  CHECK((flipped - f).norm() <= 1e-6f * f.norm());
  CHECK(aerodynamic_force_of<float>(r1.cast<float>(), r2.cast<float>(), r2.cast<float>(),
                                    v1.cast<float>(), v2.cast<float>(), v3.cast<float>(),
                                    air.cast<float>(), 1.225f, 1.1f)
            .isZero());
  const Vec3f still = air.cast<float>();
  CHECK(aerodynamic_force_of<float>(r1.cast<float>(), r2.cast<float>(), r3.cast<float>(), still,
                                    still, still, still, 1.225f, 1.1f)
            .isZero());
}

TEST_CASE("float: a flag in the wind steps its air in float, on any number of threads") {
  // A cloth in a gusty wind: the float room sums the air on floats (every number it writes is a
  // float), stays near the double run, and gives the same bits on 1 to 4 threads (the triangles
  // at a border between two ranges are taken by both, each adding to its own corners).
  const std::string air = "[aerodynamics]\nwind = [6, 0, 2]\ngust = [3, 0, 1]\ngust_period = 0.2\n";
  const clothlab::Scene single = steps(cloth("symplectic-euler", 0.0005, air), 200);
  const clothlab::Scene full = steps(cloth("symplectic-euler", 0.0005, air, "double"), 200);
  const clothlab::Scene calm = steps(cloth(), 200);
  CHECK(all_floats(single.world.particles.x));
  CHECK(all_floats(single.world.particles.f));
  const Matrix3X& x = single.world.particles.x;
  const double gap = (x - full.world.particles.x).cwiseAbs().maxCoeff();
  const double moved_by_air = (x - calm.world.particles.x).cwiseAbs().maxCoeff();
  CAPTURE(gap);
  CAPTURE(moved_by_air);
  CHECK(moved_by_air > 1e-3);        // the air did move the cloth
  CHECK(gap < 1e-3 * moved_by_air);  // and float moved it as double did
  for (int threads = 2; threads <= 4; ++threads) {
    CAPTURE(threads);
    const clothlab::Scene scene = steps(cloth("symplectic-euler", 0.0005, air), 200, threads);
    CHECK((scene.world.particles.x.array() == x.array()).all());
  }
}

TEST_CASE("float: a bad precision or a scene float does not cover is an error at the key") {
  // A value that is not a precision: file, line and column of the value, what was expected.
  const std::string half = load_error(cloth("symplectic-euler", 0.0005, "", "half"));
  CHECK(half.find("float.toml:") == 0);
  CHECK(half.find("precision") != std::string::npos);
  CHECK(half.find("\"double\", \"float\"") != std::string::npos);
  // A method the float room does not cover: the error names it and says what float covers.
  for (const std::string method : {"rk4", "midpoint", "implicit-euler", "xpbd", "vbd"}) {
    CAPTURE(method);
    const std::string error = load_error(cloth(method));
    CHECK(error.find("float.toml:") == 0);
    CHECK(error.find("the method " + method) != std::string::npos);
    CHECK(error.find(std::string(clothlab::fast::kFloatCovers)) != std::string::npos);
  }
  // Effects it does not cover, named, never a quiet step in double.
  const std::string drag = load_error(cloth("symplectic-euler", 0.0005, "[drag]\narea = 0.0004\n"));
  CHECK(drag.find("the effect drag;") != std::string::npos);
  // Aerodynamics it covers.
  CHECK(
      load_error(cloth("symplectic-euler", 0.0005, "[aerodynamics]\nwind = [2, 0, 1]\n")).empty());
  const std::string two = load_error(
      cloth("symplectic-euler", 0.0005, "[drag]\narea = 0.0004\n[tearing]\nstrain = 0.5\n"));
  CHECK(two.find("the effects drag, tearing") != std::string::npos);
  CHECK(two.find(std::string(clothlab::fast::kFloatCovers)) != std::string::npos);
  // The readable engine is double only.
  // (cloth() ends in [engine]: a key added at the end goes there.)
  const std::string readable = load_error(cloth() + "fast_path = false\n");
  CHECK(readable.find("readable engine computes in double only") != std::string::npos);
  // The error is at the precision key: its line.
  const std::string text = cloth("rk4");
  long line = 1 + std::count(text.begin(), text.begin() + text.find("precision"), '\n');
  CHECK(load_error(text).find("float.toml:" + std::to_string(line) + ":") == 0);
  // double (the default) loads with anything.
  CHECK(load_error(cloth("rk4", 0.0005, "", "double")).empty());
  // A number float cannot hold (it would be inf in the float room, and the first step NaN): named,
  // at the precision key. In double the same scene loads.
  std::string stiff = cloth();
  stiff.replace(stiff.find("ks = 60"), 7, "ks = 1e39");
  const std::string beyond = load_error(stiff);
  CAPTURE(beyond);
  CHECK(beyond.find("float.toml:" + std::to_string(line) + ":") == 0);
  CHECK(beyond.find("springs.ks = 1e+39") != std::string::npos);
  CHECK(beyond.find("beyond what a float holds") != std::string::npos);
  stiff.replace(stiff.find("precision = \"float\""), 19, "precision = \"double\"");
  CHECK(load_error(stiff).empty());
  // A particle so light that 1/m is beyond float.
  std::string light = cloth();
  light.replace(light.find("mass = 0.5"), 10, "mass = 1e-37");
  CHECK(load_error(light).find("whose inverse is") != std::string::npos);
}

TEST_CASE("float: a program that adds an effect the float room does not cover gets an error") {
  clothlab::Scene scene = clothlab::parse_scene(cloth(), "float.toml");
  scene.world.step(scene.dt);
  clothlab::Scene other = clothlab::parse_scene(
      cloth("symplectic-euler", 0.0005, "[drag]\narea = 0.0004\n", "double"), "other.toml");
  for (auto& effect : other.world.force_effects) {
    if (effect->name() == "drag") scene.world.force_effects.push_back(std::move(effect));
  }
  CHECK_THROWS_WITH_AS(scene.world.step(scene.dt),
                       doctest::Contains("this world has the effect drag"), std::logic_error);
}

TEST_CASE("float: the guard stops a float run that blows up and names the step and particle") {
  // ks = 6000 N/m on 0.5/810 kg particles: w ~ sqrt(8 ks / m) ~ 5400 rad/s, so dt = 2 ms gives
  // w dt ~ 11, far past symplectic Euler's limit of 2: the stiffest mode grows at every step.
  // The energy check is set aside so that the bounds the float room checks in its pass stop it.
  std::string text =
      cloth("symplectic-euler", 0.002, "[guard]\nmax_energy_growth = 1e300\n", "float");
  text.replace(text.find("ks = 60"), 7, "ks = 6000");
  for (const std::string precision : {"float", "double"}) {
    std::string t = text;
    t.replace(t.find("precision = \"float\""), 19, "precision = \"" + precision + "\"");
    clothlab::Scene scene = clothlab::parse_scene(t, "float.toml");
    // The advisor speaks before the run, in float as in double: it reads the scene, not the
    // numbers the step computes with.
    const clothlab::TimeStepAdvice advice =
        clothlab::advise_time_step(scene.world, scene.dt, scene.step_count());
    CHECK(advice.dt_limit < scene.dt);
    CHECK_FALSE(advice.warning.empty());
    long stopped = -1;
    std::string message;
    try {
      for (int s = 0; s < 500; ++s)
        scene.world.step(scene.dt);
    } catch (const clothlab::SimulationError& e) {
      stopped = e.step();
      message = e.what();
      CHECK(e.particle() >= 0);
      CHECK(message.find("particle " + std::to_string(e.particle())) != std::string::npos);
    }
    CAPTURE(precision);
    CAPTURE(message);
    REQUIRE(stopped > 0);
    CHECK(message.find("blew up at step " + std::to_string(stopped)) != std::string::npos);
    // No NaN or infinity was let through to the state the guard saw stop.
    CHECK(stopped < 500);
  }
}

TEST_CASE("float: the advisor's stable dt runs its course in float") {
  // The scene of the cases above at its own dt: the advisor finds it stable, and the float run
  // covers its whole second without the guard stopping it, the energy check included.
  clothlab::Scene scene = clothlab::parse_scene(cloth(), "float.toml");
  const clothlab::TimeStepAdvice advice =
      clothlab::advise_time_step(scene.world, scene.dt, scene.step_count());
  CHECK(advice.warning.empty());
  CHECK(scene.dt <= advice.dt_limit);
  for (long s = 0; s < scene.step_count(); ++s)
    scene.world.step(scene.dt);
  CHECK(all_floats(scene.world.particles.x));
  CHECK(scene.world.particles.x.allFinite());
}

TEST_CASE("float: every lesson scene float covers stays near its double run") {
  // The bound. A float carries 24 bits: each rounding moves a number x by at most u |x|, with
  // u = 2^-24 ~ 6.0e-8. A step of the float room rounds each particle's x a few times (the
  // copy of the double state, x + v dt, and the forces and v that feed it, each a few
  // roundings of its own), so it adds at most about k u L of error to a position, L the
  // largest coordinate the scene reaches [m], with k a small count of roundings: k = 8 (four
  // roundings on the position's path, as many again through v and f). Where the scene does not
  // amplify a difference, these errors add up at worst, so after N steps
  //   max |x_float - x_double| <= k N u L.
  // A scene may amplify one: a contact's static friction holds a particle or lets it slide on
  // a threshold, a sheet laid symmetrically on a ball slides off one way or the other, which a
  // rounding decides, and a flag flapping in the wind or a sheet tumbling as it falls parts
  // from any nearby run by a factor at every flap. Such a scene parts from itself in double
  // just as well, so the test measures its spread D: the double run against the same run with
  // every coordinate and velocity moved by one float rounding's worth, x (1 + u r) and
  // v (1 + u r), r uniform in [-1, 1] (a seeded draw), at the start and after every step: float's
  // roundings, of float's size and at float's pace, but random (rounding to float would keep a
  // symmetric sheet symmetric, where float arithmetic does not). Where D is more than k N u L
  // the scene amplifies its roundings more than they add up, and all a test can ask is that the
  // float run stays within that spread (twice D: D is one draw of it). So the bound is
  // max(k N u L, 2 D). The measured ratios (printed) sit well under it: 0.12 or less where
  // k N u L sets it (gusty-flag), 0.26 or less where 2 D does (stiff-sheet-edge; the flag, the
  // falling sheet and cloth-on-sphere 0.05 to 0.10). A scene made to blow up must blow up in
  // float too, at the same step.
  constexpr double u = 0x1p-24;
  constexpr double k = 8.0;
  constexpr long kMaxSteps = 2000;  // the first 2000 steps of a longer run (seconds in all)
  int covered = 0, declined = 0;
  std::vector<fs::path> scenes;
  for (const auto& entry : fs::recursive_directory_iterator(CLOTHLAB_LESSONS)) {
    if (entry.path().extension() == ".toml") scenes.push_back(entry.path());
  }
  std::sort(scenes.begin(), scenes.end());
  REQUIRE(scenes.size() > 20);
  for (const fs::path& path : scenes) {
    CAPTURE(path.string());
    clothlab::Scene full = clothlab::load_scene_file(path);
    clothlab::Scene single = clothlab::load_scene_file(path);
    clothlab::Scene nudged = clothlab::load_scene_file(path);  // double, nudged at every step
    std::mt19937 random(43);
    std::uniform_real_distribution<double> r(-1.0, 1.0);
    const auto nudge = [&] {
      for (double& x : nudged.world.particles.x.reshaped())
        x *= 1.0 + u * r(random);
      for (double& v : nudged.world.particles.v.reshaped())
        v *= 1.0 + u * r(random);
    };
    nudge();
    if (!full.world.backend) {
      ++declined;  // the scene asks for the readable engine: double only
      continue;
    }
    const std::string why = clothlab::fast::use_float(single.world);
    if (!why.empty()) {
      // Declined, with the words the scene's error uses.
      CHECK(why.find(std::string(clothlab::fast::kFloatCovers)) != std::string::npos);
      ++declined;
      continue;
    }
    ++covered;
    const long n = std::min(full.step_count(), kMaxSteps);
    double reach = 0.0;  // L [m]
    // A scene made to blow up (lesson 08's stiff sheet) must blow up in float too, the guard
    // stopping it at the step where it stops the double run, or the next.
    long full_stop = -1, single_stop = -1;
    const auto step = [](clothlab::Scene& scene, long s, long& stop) {
      if (stop >= 0) return;
      try {
        scene.world.step(scene.dt);
      } catch (const clothlab::SimulationError&) {
        stop = s;
      }
    };
    for (long s = 0; s < n && full_stop < 0; ++s) {
      step(full, s, full_stop);
      step(single, s, single_stop);
      if (full_stop < 0) {
        nudged.world.step(nudged.dt);
        nudge();
        reach = std::max(reach, full.world.particles.x.cwiseAbs().maxCoeff());
      }
    }
    if (full_stop >= 0) {
      step(single, full_stop + 1, single_stop);  // the next step, where float has not stopped
      MESSAGE(path.filename().string() << ": the guard stops the double run at step " << full_stop
                                       << ", the float run at step " << single_stop);
      CHECK(single_stop >= full_stop);
      CHECK(single_stop <= full_stop + 1);
      continue;
    }
    CHECK(single_stop == -1);
    REQUIRE(single.world.backend_evaluations == n);
    // Every number the float room wrote is a float; contacts and pins then move particles in
    // double, after the step.
    if (single.world.post_step_effects.empty()) CHECK(all_floats(single.world.particles.x));
    const double L = std::max(reach, 1e-3);
    const double gap = (single.world.particles.x - full.world.particles.x).cwiseAbs().maxCoeff();
    const double spread = (nudged.world.particles.x - full.world.particles.x).cwiseAbs().maxCoeff();
    const double bound = std::max(k * static_cast<double>(n) * u * L, 2.0 * spread);
    MESSAGE(path.filename().string()
            << ": " << n << " steps, float - double " << gap << " m, spread " << spread
            << " m, bound " << bound << " m, ratio " << gap / bound);
    CHECK(gap <= bound);
  }
  MESSAGE(covered << " lesson scenes in float, " << declined << " declined");
  CHECK(covered >= 10);
}
