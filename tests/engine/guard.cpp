// The guard: a blown-up state stops the run with an error that says where and why.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/methods.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Vec3;

namespace {

// A force effect that misbehaves on purpose: from step `at` on, particle `victim` gets a NaN
// force (as a division by a zero length would give), or an infinite one (an overflow).
class NanInjector final : public clothlab::ForceEffect {
 public:
  NanInjector(const clothlab::World& world, long at, clothlab::Index victim,
              double value = std::numeric_limits<double>::quiet_NaN())
      : world_(world), at_(at), victim_(victim), value_(value) {}
  std::string_view name() const override { return "nan-injector"; }
  void add_forces(const clothlab::Particles&, const clothlab::Matrix3X&, const clothlab::Matrix3X&,
                  clothlab::Matrix3X& f) const override {
    if (world_.steps + 1 >= at_) f(1, victim_) = value_;
  }

 private:
  const clothlab::World& world_;
  long at_;
  clothlab::Index victim_;
  double value_;  // the force's y component from step `at` on: NaN, or an infinity
};

// A force along each particle's own velocity, f = c m v with c = 10 1/s: energy from nowhere,
// which grows as e^(2 c t) whatever the method.
class Pump final : public clothlab::ForceEffect {
 public:
  std::string_view name() const override { return "pump"; }
  void add_forces(const clothlab::Particles& p, const clothlab::Matrix3X&,
                  const clothlab::Matrix3X& v, clothlab::Matrix3X& f) const override {
    for (clothlab::Index i = 0; i < p.size(); ++i)
      f.col(i) += 10.0 * p.m[i] * v.col(i);
  }
};

// The message of the SimulationError that stops `world` within 1000 steps of 0.01 s.
std::string blow_up_message(clothlab::World& world) {
  try {
    for (int s = 0; s < 1000; ++s)
      world.step(0.01);
  } catch (const clothlab::SimulationError& e) {
    return e.what();
  }
  FAIL("the guard did not stop the run");
  return "";
}

}  // namespace

TEST_CASE("guard: its advice is true for the method: XPBD, local/global and VBD have no dt limit") {
  // Blamed on dt and stability limits, a blow-up under XPBD, the local/global solver or vertex
  // block descent sent a user to shrink a dt that was not the cause: none has a time-step limit
  // on its springs.
  const std::string dt_blamed = "A time step too large for the stiffness is the usual cause";
  const std::string limit_blamed = "dt is above its stability limit";
  for (const char* method : {"xpbd", "local-global", "vbd", "symplectic-euler"}) {
    CAPTURE(method);
    const bool limited = std::string(method) == "symplectic-euler";
    const std::string no_limit =
        fmt::format("{} steps the springs {}, with no time-step limit from their stiffness", method,
                    std::string(method) == "xpbd" ? "as constraints" : "implicitly");
    // Beyond a bound: a fall under 1e9 m/s^2 passes 1000 m within a step.
    clothlab::World falls = test::falling_particle(method, 1.0, Vec3::Zero(), 1e9);
    falls.guard.max_position = 1000.0;
    const std::string beyond = blow_up_message(falls);
    CAPTURE(beyond);
    CHECK(beyond.find("beyond the guard's bound of 1000 m") != std::string::npos);
    CHECK((beyond.find(dt_blamed) != std::string::npos) == limited);
    CHECK((beyond.find(no_limit) != std::string::npos) == !limited);
    // Energy that runs away: the pump's, found by the energy check.
    clothlab::World pumped;
    pumped.particles.add(Vec3::Zero(), Vec3(1, 0, 0), 1.0);
    pumped.force_effects.push_back(std::make_unique<Pump>());
    pumped.integrator = clothlab::make_integrator(method);
    const std::string ran_away = blow_up_message(pumped);
    CAPTURE(ran_away);
    CHECK(ran_away.find("simulation ran away") != std::string::npos);
    CHECK((ran_away.find(limit_blamed) != std::string::npos) == limited);
    CHECK((ran_away.find(no_limit) != std::string::npos) == !limited);
  }
}

TEST_CASE("guard: VBD with too few sweeps for its springs is told so, and the advice holds") {
  // ks = 1e7 N/m at dt = 10 ms: one sweep a step leaves the springs stretched and their energy
  // grows until the energy check stops the run. The advice names the sweeps; ten of them, or a
  // dt ten times smaller, run the same cloth through.
  const auto scene_text = [](int iterations, double dt) {
    return fmt::format(R"([cloth]
rows = 16
cols = 16
spacing = 0.02
mass = 0.5
pins = "top-corners"
[springs]
ks = 1e7
[bending]
ks = 1e5
[gravity]
[integrator]
method = "vbd"
dt = {}
duration = 1
iterations = {}
)",
                       dt, iterations);
  };
  const auto run = [](const std::string& text) {
    clothlab::Scene scene = clothlab::parse_scene(text, "vbd.toml");
    try {
      for (long s = 0; s < 100; ++s)
        scene.world.step(scene.dt);
    } catch (const clothlab::SimulationError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string what = run(scene_text(1, 0.01));
  CAPTURE(what);
  CHECK(what.find("simulation ran away") != std::string::npos);
  CHECK(what.find("its 1 sweep a step (iterations = 1) may leave them far from solved") !=
        std::string::npos);
  CHECK(what.find("more iterations, or a smaller dt") != std::string::npos);
  CHECK(what.find("a smaller dt is not the cure") == std::string::npos);
  CHECK(run(scene_text(10, 0.01)).empty());
  CHECK(run(scene_text(1, 0.001)).empty());
}

TEST_CASE("guard: an injected NaN stops the run at that step naming the particle") {
  clothlab::World world = test::falling_particle("symplectic-euler");
  for (int i = 0; i < 4; ++i)
    world.particles.add(Vec3(i, 1, 0), Vec3::Zero(), 1.0);
  world.force_effects.push_back(std::make_unique<NanInjector>(world, 5, 3));
  for (int s = 1; s < 5; ++s)
    world.step(0.01);  // steps 1-4 are clean
  try {
    world.step(0.01);
    FAIL("the guard let a NaN through");
  } catch (const clothlab::SimulationError& e) {
    const std::string what = e.what();
    CAPTURE(what);
    CHECK(e.step() == 5);
    CHECK(e.particle() == 3);
    CHECK(what.find("step 5") != std::string::npos);
    CHECK(what.find("particle 3") != std::string::npos);
    CHECK(what.find("not finite") != std::string::npos);
    CHECK(what.find("gravity, nan-injector; integrator symplectic-euler") != std::string::npos);
  }
}

TEST_CASE("guard: a force that overflows on a pinned particle is named as what it is") {
  // 1/m = 0 holds a pin against any finite force; 0 times an infinite one is a NaN, and the pin
  // is where it shows. The error says what the forces were, and that the particle is pinned.
  for (const double bad :
       {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    CAPTURE(bad);
    clothlab::World world = test::falling_particle("symplectic-euler");
    world.particles.add(Vec3(1, 1, 0), Vec3::Zero(), 1.0);
    world.particles.inv_m(1) = 0.0;  // pinned
    world.force_effects.push_back(std::make_unique<NanInjector>(world, 3, 1, bad));
    const std::string what = blow_up_message(world);
    CAPTURE(what);
    CHECK(what.find("at step 3") != std::string::npos);
    CHECK(what.find("particle 1 position is not finite") != std::string::npos);
    CHECK(what.find("The forces the step summed on it were not finite") != std::string::npos);
    CHECK(what.find("the particle is pinned (1/m = 0)") != std::string::npos);
    if (std::isinf(bad)) {
      CHECK(what.find("a force effect overflowed") != std::string::npos);
    } else {
      CHECK(what.find("a force effect gave a NaN") != std::string::npos);
    }
  }
}

TEST_CASE("guard: a position beyond the bound stops the run") {
  clothlab::World world = test::falling_particle("explicit-euler");
  world.guard.max_position = 10.0;
  // Free fall passes 10 m after sqrt(2 * 10 / 9.8) = 1.43 s: the run must stop there.
  long stopped_at = -1;
  try {
    for (int s = 0; s < 300; ++s)
      world.step(0.01);
  } catch (const clothlab::SimulationError& e) {
    stopped_at = e.step();
    CHECK(std::string(e.what()).find("beyond the guard's bound of 10 m") != std::string::npos);
  }
  CHECK(stopped_at > 140);
  CHECK(stopped_at < 150);
}

TEST_CASE("guard: a speed beyond the bound stops the run") {
  clothlab::World world = test::falling_particle("symplectic-euler");
  world.guard.max_speed = 5.0;
  CHECK_THROWS_AS(
      [&] {
        for (int s = 0; s < 100; ++s)
          world.step(0.01);
      }(),
      clothlab::SimulationError);
  CHECK(world.particles.v.cwiseAbs().maxCoeff() > 5.0);
}

TEST_CASE("guard: a calm run is never stopped") {
  clothlab::World world = test::falling_particle("symplectic-euler");
  for (int s = 0; s < 1000; ++s)
    world.step(0.001);
  CHECK(world.steps == 1000);
}

namespace {

// A hanging cloth, 24 x 20, springs and gravity: every force effect has a fast path, so with
// the Euler methods a step is one pass that also checks the state (fast/engine.hpp).
// `extra` adds tables; `ks` and `dt` set how stable it is.
clothlab::Scene hanging_cloth(const std::string& method, double ks, double dt,
                              const std::string& extra = "") {
  const std::string text = R"([cloth]
rows = 24
cols = 20
spacing = 0.02
mass = 0.5
pins = "top-corners"
[springs]
ks = )" + std::to_string(ks) +
                           R"(
kd = 0.01
[gravity]
[integrator]
method = ")" + method + R"("
dt = )" + std::to_string(dt) +
                           R"(
duration = 10.0
)" + extra;
  return clothlab::parse_scene(text, "guard.toml");
}

// How a run of up to `steps` steps ended: the error's step, particle and text, or step -1.
struct Stop {
  long step = -1;
  clothlab::Index particle = -1;
  std::string what;
};

Stop run_until_stopped(clothlab::Scene& scene, int steps) {
  try {
    for (int s = 0; s < steps; ++s)
      scene.world.step(scene.dt);
  } catch (const clothlab::SimulationError& e) {
    return {e.step(), e.particle(), e.what()};
  }
  return {};
}

}  // namespace

TEST_CASE("guard: a state spoiled between steps stops the next step before anything moves") {
  // Every way the check can run: in the Euler methods' one pass (fast path, 1 and 2 threads),
  // on the readable path, and on its own before an integrator of several passes.
  struct Setting {
    const char* method;
    bool fast;
    int threads;
  };
  for (const Setting& s :
       {Setting{"symplectic-euler", true, 1}, Setting{"symplectic-euler", true, 2},
        Setting{"explicit-euler", false, 1}, Setting{"rk4", true, 2}}) {
    CAPTURE(s.method);
    CAPTURE(s.fast);
    CAPTURE(s.threads);
    clothlab::Scene scene = hanging_cloth(s.method, 50.0, 0.001);
    clothlab::World& world = scene.world;
    if (!s.fast) world.backend.reset();
    world.threads = s.threads;
    for (int k = 0; k < 10; ++k)
      world.step(scene.dt);
    // Code between steps puts a NaN into one particle's velocity.
    world.particles.v(2, 301) = std::numeric_limits<double>::quiet_NaN();
    const clothlab::Matrix3X x_before = world.particles.x;
    const Stop stop = run_until_stopped(scene, 1);
    CAPTURE(stop.what);
    CHECK(stop.step == 11);
    CHECK(stop.particle == 301);
    CHECK(stop.what.find("blew up before step 11") != std::string::npos);
    CHECK(stop.what.find("velocity is not finite") != std::string::npos);
    // Nothing moved, and the step was not counted.
    CHECK((world.particles.x.array() == x_before.array()).all());
    CHECK(world.steps == 10);
  }
}

TEST_CASE("guard: a blow-up stops the fast path's one pass as it stops the readable path") {
  // Far too stiff for dt: the cloth blows up within a few dozen steps. The fast path checks the
  // state in its one pass (1 and 2 threads), or after a post-step effect ([ground]) on its own;
  // either way the run must stop at the same step, at the same particle, with the same words.
  for (const std::string extra : {"", "[ground]\ny = -5.0\n"}) {
    for (const char* method : {"symplectic-euler", "explicit-euler"}) {
      CAPTURE(extra);
      CAPTURE(method);
      clothlab::Scene readable = hanging_cloth(method, 4e5, 0.002, extra);
      readable.world.backend.reset();
      const Stop expected = run_until_stopped(readable, 2000);
      REQUIRE(expected.step > 0);
      for (int threads : {1, 2}) {
        CAPTURE(threads);
        clothlab::Scene fast = hanging_cloth(method, 4e5, 0.002, extra);
        fast.world.threads = threads;
        const Stop stop = run_until_stopped(fast, 2000);
        CHECK(fast.world.backend_evaluations > 0);
        CHECK(stop.step == expected.step);
        CHECK(stop.particle == expected.particle);
        CHECK(stop.what == expected.what);
      }
    }
  }
}
