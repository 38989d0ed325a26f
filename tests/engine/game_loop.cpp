// The game-loop interface (lesson 11): fixed substeps whatever the frame times, input that lands
// on a substep, the cap, wind ramps, dragged pins and normals for rendering.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "clothlab/core/guard.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "scene/simulation.hpp"

using clothlab::Index;
using clothlab::Matrix3X;
using clothlab::Simulation;
using clothlab::Vec3;

namespace {

// A small flag, 6 x 6 particles 5 cm apart, pinned at two corners, in a breeze. dt = 1 ms is
// the awkward case: neither 1 ms nor 1/60 s is exact in binary, and a plain accumulator counts
// 1999 steps in 120 frames of 1/60 s (see exercises/11_game_loop.cpp, hint 2).
const char* kFlag = R"(
[cloth]
rows = 6
cols = 6
spacing = 0.05
mass = 0.05
pins = "top-corners"
[springs]
ks = 40
kd = 0.02
[gravity]
[aerodynamics]
wind = [1.0, 0.0, 3.0]
[integrator]
dt = 0.001
duration = 10
)";

Simulation flag(long max_substeps = 100000) {
  return Simulation(clothlab::parse_scene(kFlag, "<flag>"), max_substeps);
}

// Frame times that add up to `total` [s], cut at `count - 1` random points (fixed seed).
std::vector<double> random_frames(double total, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> cut(0.0, total);
  std::vector<double> cuts{0.0, total};
  for (int k = 1; k < count; ++k)
    cuts.push_back(cut(rng));
  std::sort(cuts.begin(), cuts.end());
  std::vector<double> frames;
  for (size_t k = 1; k < cuts.size(); ++k)
    frames.push_back(cuts[k] - cuts[k - 1]);
  return frames;
}

std::vector<double> even_frames(double total, int count) {
  return std::vector<double>(static_cast<size_t>(count), total / count);
}

// Runs `frames` through a fresh flag; returns the substeps taken.
long run(Simulation& sim, const std::vector<double>& frames) {
  long steps = 0;
  for (double frame : frames)
    steps += sim.advance(frame);
  return steps;
}

bool same_state(const Simulation& a, const Simulation& b) {
  return a.world().particles.x == b.world().particles.x &&
         a.world().particles.v == b.world().particles.v;
}

// The acceleration of the centre of mass, F / M [m/s^2], at the current state: internal forces
// cancel, so this is the wind's push (and gravity).
Vec3 centre_acceleration(const Simulation& sim) {
  const clothlab::World& w = sim.world();
  Matrix3X f(3, w.particles.size());
  w.compute_forces(w.particles.x, w.particles.v, f);
  return f.rowwise().sum() / w.particles.m.sum();
}

}  // namespace

TEST_SUITE("game loop") {
  TEST_CASE("the same total time gives the same substeps and the same state bit for bit") {
    // 2 s of frames: 120 at 60 fps, 60 at 30 fps, 97 of random length, one frame of 2 s. Each
    // must take 2000 steps of 1 ms and end in exactly the state of 2000 plain World::steps.
    Simulation reference = flag();
    for (int k = 0; k < 2000; ++k)
      reference.world().step(reference.dt());

    const std::vector<std::vector<double>> splits = {
        even_frames(2.0, 120), even_frames(2.0, 60), random_frames(2.0, 97, 11), {2.0}};
    for (const auto& frames : splits) {
      CAPTURE(frames.size());
      Simulation sim = flag();
      CHECK(run(sim, frames) == 2000);
      CHECK(sim.steps() == 2000);
      CHECK(sim.leftover() < 1e-9);
      CHECK(sim.dropped_time() == 0.0);
      CHECK(same_state(sim, reference));
    }
  }

  TEST_CASE("a frame's substeps go to the world at once when nothing happens between them") {
    // On two threads a substep taken alone wakes them once; taken at once (World::advance), the
    // engine room keeps the state between them and wakes them once a run of steps. The state is
    // that of plain World::steps, bit for bit. (A flag of 24 x 24: the 6 x 6 one's rows of
    // springs are too short for the engine room, which leaves them to the effect's own loop.)
    std::string text = kFlag;
    text.replace(text.find("rows = 6\ncols = 6"), 17, "rows = 24\ncols = 24");
    text.replace(text.find("mass = 0.05"), 11, "mass = 0.8");  // the same mass a particle
    const auto big_flag = [&] { return Simulation(clothlab::parse_scene(text, "<flag>"), 100000); };
    Simulation reference = big_flag();
    reference.world().threads = 2;
    for (int k = 0; k < 600; ++k)
      reference.world().step(reference.dt());
    Simulation sim = big_flag();
    sim.world().threads = 2;
    CHECK(run(sim, even_frames(0.6, 20)) == 600);  // 30 substeps a frame
    CHECK(same_state(sim, reference));
    CHECK(sim.world().thread_wakes() < reference.world().thread_wakes() / 4);
  }

  TEST_CASE("a force switched on at a substep gives the same state whatever the frames") {
    // A push on the free bottom corner from step 300 to step 500, applied by the per-substep
    // callback; 1 s of frames cut three ways.
    const Index corner = 35;
    const auto push = [corner](Simulation& s) {
      if (s.steps() == 300) s.apply_force(corner, Vec3(0.0, 0.0, 0.5));
      if (s.steps() == 500) s.clear_forces();
    };
    std::vector<Simulation> sims;
    for (const auto& frames :
         {even_frames(1.0, 60), even_frames(1.0, 30), random_frames(1.0, 45, 3)}) {
      Simulation sim = flag();
      sim.on_substep(push);
      CHECK(run(sim, frames) == 1000);
      sims.push_back(std::move(sim));
    }
    CHECK(same_state(sims[0], sims[1]));
    CHECK(same_state(sims[0], sims[2]));
    // ... and the push did something: without it the corner ends elsewhere.
    Simulation calm = flag();
    run(calm, even_frames(1.0, 60));
    CHECK((calm.positions().col(corner) - sims[0].positions().col(corner)).norm() > 1e-3);
  }

  TEST_CASE("the leftover and alpha follow the accumulator") {
    Simulation sim = flag();
    Matrix3X before;  // the positions before the latest substep
    sim.on_substep([&](Simulation& s) { before = s.positions(); });
    // 2.5 ms: two steps of 1 ms, 0.5 ms left, half way to the next state.
    CHECK(sim.advance(0.0025) == 2);
    CHECK(sim.leftover() == doctest::Approx(0.0005).epsilon(1e-9));
    CHECK(sim.alpha() == doctest::Approx(0.5).epsilon(1e-9));
    // 0.4 ms more: no step, 0.9 of the way. What is drawn is that mix of the last two states.
    CHECK(sim.advance(0.0004) == 0);
    CHECK(sim.alpha() == doctest::Approx(0.9).epsilon(1e-9));
    CHECK((sim.interpolated_positions() - (0.1 * before + 0.9 * sim.positions())).norm() < 1e-12);
    CHECK((sim.interpolated_positions() - sim.positions()).norm() > 1e-9);  // not the last state
    // 0.1 ms more makes 3 ms: one more step and nothing left; alpha 0 draws the state one step
    // back, where the substep started.
    CHECK(sim.advance(0.0001) == 1);
    CHECK(sim.steps() == 3);
    CHECK(sim.alpha() < 1e-9);
    CHECK((sim.interpolated_positions() - before).norm() < 1e-12);

    // Random frames: alpha always in [0, 1), and steps dt + leftover is the time given.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> frame(0.0, 0.02);
    Simulation random = flag();
    double total = 0.0;
    for (int k = 0; k < 300; ++k) {
      const double f = frame(rng);
      total += f;
      random.advance(f);
      REQUIRE(random.alpha() >= 0.0);
      REQUIRE(random.alpha() < 1.0);
    }
    CHECK(static_cast<double>(random.steps()) * random.dt() + random.leftover() ==
          doctest::Approx(total).epsilon(1e-12));
  }

  TEST_CASE("the cap drops the time beyond it and reports it") {
    Simulation sim = flag(10);
    // 25.5 ms asks for 25 steps of 1 ms; 10 are taken, 15 ms dropped, 0.5 ms kept.
    CHECK(sim.advance(0.0255) == 10);
    CHECK(sim.steps() == 10);
    CHECK(sim.dropped_time() == doctest::Approx(0.015).epsilon(1e-9));
    CHECK(sim.leftover() == doctest::Approx(0.0005).epsilon(1e-9));
    // Under the cap nothing is dropped.
    CHECK(sim.advance(0.0095) == 10);
    CHECK(sim.dropped_time() == doctest::Approx(0.015).epsilon(1e-9));
    // The default cap is a quarter of a second of steps.
    CHECK(flag(0).max_substeps() == 250);
  }

  TEST_CASE("a ramped wind changes the force a little each substep and an instant one jumps") {
    // A free sheet in calm air (no pins, no gravity), then wind (0, 0, 5) m/s face-on. Instant,
    // the push goes from 0 to a0 = 1/2 rho |w|^2 cd A / M in one substep. Ramped over N = 100
    // substeps the wind grows by w / N a step, and the push, which goes with |u|^2 (u = w - v
    // the air's speed against the sheet, |u| <= |w|), grows by at most (2 |u| + |w| / N) |w| / N
    // ... that is by at most (2 + 1/N) a0 / N per substep: 3 a0 / N is a safe bound.
    const char* calm = R"(
[cloth]
rows = 5
cols = 5
spacing = 0.1
mass = 0.1
[springs]
ks = 40
kd = 0.02
[aerodynamics]
wind = [0.0, 0.0, 0.0]
[integrator]
dt = 0.001
duration = 10
)";
    const auto largest_change = [&](double ramp_time) {
      Simulation sim(clothlab::parse_scene(calm, "<calm>"));
      for (int k = 0; k < 20; ++k)
        sim.advance(0.001);
      sim.set_wind(Vec3(0.0, 0.0, 5.0), ramp_time);
      Vec3 a = centre_acceleration(sim);
      double worst = 0.0;
      for (int k = 0; k < 300; ++k) {
        CHECK(sim.advance(0.001) == 1);
        const Vec3 next = centre_acceleration(sim);
        worst = std::max(worst, (next - a).norm());
        a = next;
      }
      CHECK(sim.wind() == Vec3(0.0, 0.0, 5.0));
      return worst;
    };
    // a0: the whole sheet, 0.4 m x 0.4 m, face-on in 5 m/s.
    const double a0 = 0.5 * clothlab::kAirDensity * 25.0 * 1.0 * 0.16 / 0.1;
    const double instant = largest_change(0.0);
    const double ramped = largest_change(0.1);
    // Within 3 %: when the acceleration is measured the sheet has already moved off at a0 dt =
    // 0.025 m/s, 0.5 % of the wind's speed, which lowers the push by 1 %.
    CHECK(instant == doctest::Approx(a0).epsilon(0.03));
    CHECK(ramped <= 3.0 * a0 / 100.0);
    CHECK(ramped > 0.0);
  }

  TEST_CASE("a moved pin reaches its target in equal shares and stays pinned") {
    Simulation sim = flag();
    const Index corner = 0;
    const Vec3 start = sim.positions().col(corner);
    const Vec3 target = start + Vec3(0.1, 0.05, 0.0);
    std::vector<Vec3> path;
    std::vector<Vec3> velocities;
    sim.on_substep([&](Simulation& s) {
      path.push_back(s.positions().col(corner));
      velocities.push_back(s.world().particles.v.col(corner));
    });
    sim.move_pin(corner, target);
    const long n = sim.advance(1.0 / 60.0);
    REQUIRE(n == 16);
    path.push_back(sim.positions().col(corner));
    CHECK(sim.positions().col(corner) == target);
    CHECK(sim.world().particles.inv_m[corner] == 0.0);
    CHECK(sim.world().particles.v.col(corner) == Vec3::Zero());
    for (size_t k = 1; k < path.size(); ++k)  // (target - start) / 16 per substep
      CHECK((path[k] - path[k - 1] - (target - start) / 16.0).norm() < 1e-12);
    // ... at the velocity that carries it there, (target - start) / (16 dt), from the first
    // substep on (seen before the second and later ones): the springs see it move.
    for (size_t k = 1; k < velocities.size(); ++k)
      CHECK((velocities[k] - (target - start) / (16.0 * sim.dt())).norm() < 1e-9);
    // Its neighbour felt the pull: it lies further along +x than in a flag left alone.
    Simulation alone = flag();
    alone.advance(1.0 / 60.0);
    CHECK(sim.positions()(0, 1) > alone.positions()(0, 1) + 1e-6);
    // Without a new move it stays where it is.
    sim.advance(0.1);
    CHECK(sim.positions().col(corner) == target);
    // Only a pinned particle can be moved; a pin can be made and released.
    CHECK_THROWS_AS(sim.move_pin(20, target), std::logic_error);
    sim.pin(20);
    CHECK_NOTHROW(sim.move_pin(20, target));
    sim.unpin(20);
    CHECK(sim.world().particles.inv_m[20] > 0.0);
  }

  TEST_CASE("normals are unit length and agree on a flat cloth") {
    Simulation sim = flag();
    const Matrix3X& n = sim.normals();
    REQUIRE(n.cols() == sim.positions().cols());
    for (Index i = 0; i < n.cols(); ++i) {
      CHECK(n.col(i).norm() == doctest::Approx(1.0).epsilon(1e-12));
      // The flag hangs in the x-y plane: every normal is +z or -z, and all the same one.
      CHECK(std::abs(n(2, i)) == doctest::Approx(1.0).epsilon(1e-12));
      CHECK(n.col(i).dot(n.col(0)) > 0.999999);
    }
    // The same buffer is handed out again, refreshed after a step.
    const Matrix3X* first = &sim.normals();
    sim.advance(0.5);
    CHECK(&sim.normals() == first);
    CHECK(sim.normals().col(35).norm() == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(std::abs(sim.normals()(2, 35)) < 0.999999);  // the wind has turned the sheet

    // A rope has no surface: its normals are zero.
    Simulation rope(clothlab::parse_scene(R"(
[rope]
start = [0.0, 1.0, 0.0]
end = [1.0, 1.0, 0.0]
particles = 5
mass = 0.1
pins = "first"
[springs]
ks = 50
[integrator]
dt = 0.001
duration = 1
)",
                                          "<rope>"));
    CHECK(rope.normals().cols() == 5);
    CHECK(rope.normals().isZero(0.0));
  }

  TEST_CASE("errors say what went wrong") {
    Simulation sim = flag();
    CHECK_THROWS_AS(sim.advance(-0.01), std::invalid_argument);
    CHECK_THROWS_AS(sim.advance(std::nan("")), std::invalid_argument);
    CHECK_THROWS_AS(sim.apply_force(36, Vec3::Zero()), std::out_of_range);
    CHECK_THROWS_AS(sim.set_wind(Vec3::Zero(), -1.0), std::invalid_argument);
    // No [aerodynamics]: no wind to change.
    Simulation still(clothlab::parse_scene(R"(
[cloth]
rows = 3
cols = 3
spacing = 0.1
mass = 0.1
[springs]
ks = 10
[integrator]
dt = 0.001
duration = 1
)",
                                           "<still>"));
    try {
      still.set_wind(Vec3(1.0, 0.0, 0.0), 0.0);
      FAIL("set_wind on a scene without [aerodynamics] did not throw");
    } catch (const std::logic_error& error) {
      CHECK(std::string(error.what()).find("[aerodynamics]") != std::string::npos);
    }
    // The guard's error comes through advance with its message: a spring far too stiff for
    // dt = 10 ms blows up.
    Simulation stiff(clothlab::parse_scene(R"(
[cloth]
rows = 3
cols = 3
spacing = 0.1
mass = 0.01
pins = "top-corners"
[springs]
ks = 1e6
[gravity]
[integrator]
dt = 0.01
duration = 100
)",
                                           "<stiff>"));
    try {
      for (int k = 0; k < 1000; ++k)
        stiff.advance(1.0 / 60.0);
      FAIL("the stiff cloth did not blow up");
    } catch (const clothlab::SimulationError& error) {
      CHECK(std::string(error.what()).find("step") != std::string::npos);
    }
  }
}
