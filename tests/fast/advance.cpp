// World::advance: steps taken several at once, the state kept in the engine room's layout between
// them (engine/fast/resident.hpp), are the steps World::step takes one at a time, bit for bit:
// the state, the forces, the time, the counts and the guard's errors.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "clothlab/core/guard.hpp"
#include "fast/copies.hpp"
#include "fast_util.hpp"

using clothlab::Index;

namespace {

// A hanging cloth in a gusty wind (a force that changes with time: each step must be told its
// own), in `precision`, with `method`.
std::string windy_cloth(const std::string& method, const std::string& precision,
                        const std::string& extra = "") {
  return test::hanging_cloth(24, 21) +
         "[aerodynamics]\nwind = [6, 0, 2]\ngust = [3, 0, 1]\ngust_period = 0.05\n"
         "[integrator]\nmethod = \"" +
         method + "\"\ndt = 0.0005\nduration = 1.0\n" + extra + "[engine]\nprecision = \"" +
         precision + "\"\n";
}

struct Run {
  clothlab::Scene scene;
  long wakes = 0;
};

// The scene on `threads` threads: one step, then `count` steps, at once (advance) or one at a time.
Run stepped(const std::string& text, int threads, long count, bool at_once, bool fast = true) {
  Run run{clothlab::parse_scene(text, "advance.toml")};
  clothlab::World& world = run.scene.world;
  if (!fast) world.backend.reset();
  world.threads = threads;
  world.step(run.scene.dt);
  const long before = world.thread_wakes();
  if (at_once) {
    world.advance(run.scene.dt, count);
  } else {
    for (long s = 0; s < count; ++s)
      world.step(run.scene.dt);
  }
  run.wakes = world.thread_wakes() - before;
  return run;
}

void check_same(const clothlab::World& a, const clothlab::World& b) {
  CHECK(test::identical(a.particles.x, b.particles.x));
  CHECK(test::identical(a.particles.v, b.particles.v));
  CHECK(test::identical(a.particles.f, b.particles.f));
  CHECK(a.t == b.t);
  CHECK(a.steps == b.steps);
  CHECK(a.force_evaluations == b.force_evaluations);
}

// The SimulationError the scene's steps end with, and the world they leave.
struct Stop {
  long step = -1;
  Index particle = -1;
  std::string message;
};

Stop stop_of(clothlab::World& world, double dt, long count, bool at_once) {
  Stop stop;
  try {
    if (at_once) {
      world.advance(dt, count);
    } else {
      for (long s = 0; s < count; ++s)
        world.step(dt);
    }
  } catch (const clothlab::SimulationError& e) {
    stop = {e.step(), e.particle(), e.what()};
  }
  return stop;
}

}  // namespace

TEST_CASE("advance: steps at once are the steps one at a time, bit for bit, in double and float") {
  // 100 steps after the first cross the guard's energy checks at 32, 64 and 96: the run of steps
  // stops at each, hands the state back for the check, and goes on.
  for (const std::string method : {"symplectic-euler", "explicit-euler"}) {
    for (const std::string precision : {"double", "float"}) {
      CAPTURE(method);
      CAPTURE(precision);
      const std::string text = windy_cloth(method, precision);
      // Double: against the lecture's path itself; float: against the float room's steps.
      const Run one = stepped(text, 1, 100, false, precision == "float");
      for (int threads = 1; threads <= 4; ++threads) {
        CAPTURE(threads);
        const Run at_once = stepped(text, threads, 100, true);
        check_same(at_once.scene.world, one.scene.world);
        if (threads == 1) continue;
        // It did keep the state between steps: one wake for each run of steps (four, between
        // the checks) and for each energy check's spring sets, where one at a time wakes the
        // threads at every step.
        const Run each = stepped(text, threads, 100, false);
        check_same(each.scene.world, one.scene.world);
        CHECK(each.wakes >= 100);
        CHECK(at_once.wakes < 20);
      }
    }
  }
}

TEST_CASE("advance: blocks of any size give the steps one at a time, bit for bit") {
  // Each thread takes its particles through a step pass_block at a time: clears their forces,
  // adds every effect's, moves them (resident.hpp). Blocks of one particle, shorter than a row,
  // ending mid-row, and larger than the cloth; across the energy checks at 32 and 64.
  const std::string text = windy_cloth("symplectic-euler", "double");
  const Run one = stepped(text, 1, 70, false, false);
  for (const Index block : {Index{1}, Index{29}, Index{100}, Index{100000}}) {
    for (int threads : {1, 2, 3}) {
      CAPTURE(block);
      CAPTURE(threads);
      clothlab::Scene scene = clothlab::parse_scene(text, "advance.toml");
      clothlab::World& world = scene.world;
      world.threads = threads;
      test::engine_of(world).pass_block = block;
      world.step(scene.dt);
      world.advance(scene.dt, 70);
      check_same(world, one.scene.world);
    }
  }
}

TEST_CASE("advance: a split of the particles between threads changes no bit") {
  const std::string text = windy_cloth("symplectic-euler", "double");
  const Run one = stepped(text, 1, 40, false, false);
  clothlab::Scene scene = clothlab::parse_scene(text, "advance.toml");
  clothlab::World& world = scene.world;
  world.threads = 3;
  world.step(scene.dt);
  const Index n = world.particles.size();
  // Uneven, an empty piece, a piece of one particle: between and within the runs of steps.
  const std::vector<std::vector<Index>> splits{{0, 0, 1, n}, {0, n / 5, n - 3, n}, {0, 7, 300, n}};
  for (const auto& split : splits) {
    world.set_particle_bounds(split);
    world.advance(scene.dt, 13);
  }
  world.advance(scene.dt, 1);
  check_same(world, one.scene.world);
}

TEST_CASE("advance: the guard stops a run of steps where it stops the steps one at a time") {
  // ks = 6000 N/m with dt = 2 ms: far past symplectic Euler's limit, the cloth blows up. With the
  // energy check set aside, the bounds the move checks stop it, at the step that crossed them.
  for (const std::string precision : {"double", "float"}) {
    CAPTURE(precision);
    std::string text =
        windy_cloth("symplectic-euler", precision, "[guard]\nmax_energy_growth = 1e300\n");
    text.replace(text.find("ks = 60"), 7, "ks = 6000");
    text.replace(text.find("dt = 0.0005"), 11, "dt = 0.002");
    for (int threads : {1, 2}) {
      CAPTURE(threads);
      clothlab::Scene a = clothlab::parse_scene(text, "advance.toml");
      clothlab::Scene b = clothlab::parse_scene(text, "advance.toml");
      a.world.threads = b.world.threads = threads;
      a.world.step(a.dt);
      b.world.step(b.dt);
      const Stop at_once = stop_of(a.world, a.dt, 500, true);
      const Stop each = stop_of(b.world, b.dt, 500, false);
      CAPTURE(at_once.message);
      REQUIRE(each.step > 1);
      CHECK(each.step < 500);
      CHECK(at_once.step == each.step);
      CHECK(at_once.particle == each.particle);
      CHECK(at_once.message == each.message);
      check_same(a.world, b.world);
    }
  }
}

TEST_CASE("advance: a state bad before the steps is the guard's error, and nothing moves") {
  for (const std::string precision : {"double", "float"}) {
    CAPTURE(precision);
    const std::string text = windy_cloth("symplectic-euler", precision);
    clothlab::Scene a = clothlab::parse_scene(text, "advance.toml");
    clothlab::Scene b = clothlab::parse_scene(text, "advance.toml");
    for (clothlab::Scene* scene : {&a, &b}) {
      scene->world.threads = 2;
      scene->world.step(scene->dt);
      scene->world.particles.x(1, 100) = 1e9;  // dragged far off between two steps
    }
    const clothlab::Matrix3X x = a.world.particles.x;
    const Stop at_once = stop_of(a.world, a.dt, 10, true);
    const Stop each = stop_of(b.world, b.dt, 10, false);
    CAPTURE(at_once.message);
    CHECK(at_once.particle == 100);
    CHECK(at_once.step == each.step);
    CHECK(at_once.message == each.message);
    CHECK(test::identical(a.world.particles.x, x));
    CHECK(a.world.steps == 1);
  }
}

namespace {

// A sheet dropped flat onto a ball standing on the ground (lesson 05's cloth-on-sphere, coarser):
// by 2 s its middle rests on the ball and its corners have come down to the floor, with the
// given ground model.
std::string draped_cloth(const std::string& ground) {
  return R"([cloth]
rows = 16
cols = 16
spacing = 0.08
origin = [-0.6, 0.7, -0.6]
plane = "horizontal"
mass = 0.3
pins = "none"
[springs]
ks = 100.0
kd = 0.2
shear_ks = 20.0
[gravity]
g = [0.0, -9.8, 0.0]
[sphere]
centre = [0.0, 0.35, 0.0]
radius = 0.3
e = 0.0
mu_s = 0.5
mu_d = 0.4
[ground]
)" + ground +
         R"(
[integrator]
method = "symplectic-euler"
dt = 0.0005
duration = 1.0
)";
}

}  // namespace

TEST_CASE("advance: the ground and spheres ride along in a run of steps, bit for bit") {
  // Each moved particle meets the contacts in the world's order, from the state its step began
  // with (the copies the step read): the state, forces, time and counts of step() one at a time
  // on the lecture's path, after 4000 steps in which particles land on a ball and on the
  // ground.
  for (const std::string ground :
       {"e = 0.3\nmu_s = 0.5\nmu_d = 0.4", "model = \"simple\"\ne = 0.3\nfriction = 0.2"}) {
    CAPTURE(ground);
    const std::string text = draped_cloth(ground);
    const Run one = stepped(text, 1, 4000, false, false);
    // The steps did what is claimed of them: some particles rest on the ball, some on the floor.
    const clothlab::Particles& p = one.scene.world.particles;
    Index on_ball = 0, on_floor = 0;
    for (Index i = 0; i < p.size(); ++i) {
      on_ball += std::abs((p.x.col(i) - clothlab::Vec3(0.0, 0.35, 0.0)).norm() - 0.3) < 1e-3;
      on_floor += p.x(1, i) < 1e-3;
    }
    CAPTURE(on_ball);
    CAPTURE(on_floor);
    CHECK(on_ball > 20);
    CHECK(on_floor > 0);
    for (int threads = 1; threads <= 4; ++threads) {
      CAPTURE(threads);
      const Run at_once = stepped(text, threads, 4000, true);
      check_same(at_once.scene.world, one.scene.world);
      if (threads > 1) CHECK(at_once.wakes < 500);  // a run of steps every 32, not a wake a step
    }
  }
}

TEST_CASE("advance: in a run of steps, the guard tests the state the contacts leave") {
  // A particle thrown down at 1000 m/s: step 1 (the world's own) takes it to y = -0.1 m; step 2,
  // the run's first, to -1.1 m, past the guard's 1 m, but the ground at -0.5 m puts it back on
  // its surface, and the step stands, as after World::step, whose guard looks after the contacts.
  // The bounce (e = 0.3) then carries it up past 1 m a few steps later, where both stop alike.
  const std::string text = R"([[particle]]
position = [0.0, 0.9, 0.0]
velocity = [0.0, -1000.0, 0.0]
mass = 1.0
[gravity]
[ground]
y = -0.5
e = 0.3
[integrator]
method = "symplectic-euler"
dt = 0.001
duration = 1.0
[guard]
max_position = 1.0
)";
  clothlab::Scene a = clothlab::parse_scene(text, "a.toml");
  clothlab::Scene b = clothlab::parse_scene(text, "b.toml");
  b.world.backend.reset();  // the lecture's path, one step at a time
  a.world.threads = 2;
  const long wakes = a.world.thread_wakes();
  const Stop at_once = stop_of(a.world, a.dt, 20, true);
  CHECK(a.world.thread_wakes() - wakes <= 3);  // the steps after the first, one run of them
  const Stop each = stop_of(b.world, b.dt, 20, false);
  CAPTURE(at_once.message);
  CAPTURE(each.message);
  CHECK(each.step > 2);
  CHECK(at_once.step == each.step);
  CHECK(at_once.message == each.message);
  check_same(a.world, b.world);
}

TEST_CASE(
    "advance: a world with another post-step effect takes its steps one at a time, the same") {
  // A plane (a ramp): the steps are the world's own (its contacts read the world's state); the
  // result is still that of step().
  const std::string text = test::hanging_cloth(16, 16) +
                           "[[plane]]\npoint = [0, -0.2, 0]\nnormal = [0.2, 1, 0]\n[integrator]\n"
                           "method = \"symplectic-euler\"\ndt = 0.001\nduration = 1.0\n";
  const Run one = stepped(text, 1, 300, false, false);
  const Run at_once = stepped(text, 2, 300, true);
  check_same(at_once.scene.world, one.scene.world);
  CHECK(at_once.wakes >= 300);
}

TEST_CASE("advance: in float, a position one float past the guard's bound stops the step") {
  // The float room's run of steps tests its new state in float, against the bound rounded down
  // to a float; the test must be the double one all the same. One particle, no force, moves by
  // v dt = 2^-13 m/s x 2^-10 s = 2^-23 m a step, exactly, from x = 1 - 2^-23 m: to 1 m after
  // step 1 (the world's own step: the guard's first), to 1 + 2^-23 m after step 2 (the first of
  // the run), past a bound of 1.00000007 m. Rounded to the nearest float, that bound would be
  // 1 + 2^-23 itself, and the step would pass; the next would stop.
  const std::string text = R"([[particle]]
position = [0.99999988079071044921875, 0.0, 0.0]
velocity = [0.0001220703125, 0.0, 0.0]
mass = 1.0
[integrator]
method = "symplectic-euler"
dt = 0.0009765625
duration = 1.0
[guard]
max_position = 1.00000007
[engine]
precision = "float"
)";
  for (const bool at_once : {true, false}) {
    CAPTURE(at_once);
    clothlab::Scene scene = clothlab::parse_scene(text, "advance.toml");
    const Stop stop = stop_of(scene.world, scene.dt, 4, at_once);
    CAPTURE(stop.message);
    CHECK(stop.step == 2);
    CHECK(stop.particle == 0);
    CHECK(scene.world.particles.x(0, 0) == 1.0 + 0x1p-23);  // the state the guard stopped at
  }
}

TEST_CASE("advance: in float, the steps read the masses the particles have now") {
  // The float room rounds the masses and their inverses to float once for a run of steps; a
  // program that changes them between two runs must see the new ones used: the same bits as
  // World::step in float, and near the double run (three times the mass under the same gravity:
  // with the old masses in f = m g the cloth would fall at a third of g, millimetres off).
  const auto heavier = [](clothlab::World& world) {
    clothlab::Particles& p = world.particles;
    for (Index i = 0; i < p.size(); ++i) {
      if (p.inv_m(i) == 0.0) continue;  // pinned
      p.m(i) *= 3.0;
      p.inv_m(i) = 1.0 / p.m(i);
    }
  };
  for (const bool at_once : {true, false}) {
    CAPTURE(at_once);
    clothlab::Scene a = clothlab::parse_scene(windy_cloth("symplectic-euler", "float"), "a.toml");
    clothlab::Scene b = clothlab::parse_scene(windy_cloth("symplectic-euler", "float"), "b.toml");
    clothlab::Scene d = clothlab::parse_scene(windy_cloth("symplectic-euler", "double"), "d.toml");
    for (clothlab::Scene* scene : {&a, &b, &d}) {
      scene->world.threads = 2;
      scene->world.step(scene->dt);
      stop_of(scene->world, scene->dt, 40, at_once && scene == &a);
      heavier(scene->world);
    }
    const Stop stop = stop_of(a.world, a.dt, 40, at_once);
    CAPTURE(stop.message);
    stop_of(b.world, b.dt, 40, false);
    stop_of(d.world, d.dt, 40, false);
    check_same(a.world, b.world);
    const double off = (a.world.particles.x - d.world.particles.x).cwiseAbs().maxCoeff();
    CAPTURE(off);
    CHECK(off < 1e-5);
  }
}

namespace {

// Every row of `arrays` (x, v or f of a copy) starts on a cache line; no two rows overlap, each
// taken whole, its padding included; and no two of them start within `min_lines` lines of the
// same place in a 4 KiB page.
template <class S>
void check_rows(const std::vector<const clothlab::fast::SoA3Of<S>*>& arrays, Index n,
                int min_lines) {
  struct Row {
    std::uintptr_t begin, end;
  };
  std::vector<Row> rows;
  for (const auto* a : arrays) {
    REQUIRE(a->cols() >= n);
    for (Index r = 0; r < 3; ++r) {
      const auto begin = reinterpret_cast<std::uintptr_t>(a->data() + r * a->cols());
      rows.push_back({begin, begin + static_cast<std::uintptr_t>(a->cols()) * sizeof(S)});
    }
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    CAPTURE(i);
    CHECK(rows[i].begin % 64 == 0);
    for (size_t j = 0; j < i; ++j) {
      CAPTURE(j);
      CHECK((rows[i].end <= rows[j].begin || rows[j].end <= rows[i].begin));
      const long a = static_cast<long>(rows[i].begin % 4096 / 64);
      const long b = static_cast<long>(rows[j].begin % 4096 / 64);
      CHECK(std::min((a - b + 64) % 64, (b - a + 64) % 64) >= min_lines);
    }
  }
}

template <class S>
void check_layouts() {
  for (const Index n : {Index{1}, Index{100}, Index{4096}, Index{16384}, Index{70001}}) {
    CAPTURE(n);
    clothlab::fast::CopiesOf<S> one;
    one.resize(n);
    check_rows<S>({&one.x, &one.v, &one.f}, n, 2);
    // A run of steps' two copies: two of x and v, and the one f they share.
    clothlab::fast::ResidentOf<S> two;
    for (const Index m : {n, n / 2 + 1, 2 * n}) {  // then smaller, then larger: laid out again
      CAPTURE(m);
      two.resize(m);
      check_rows<S>({&two.a.x, &two.a.v, &two.a.f, &two.b.x, &two.b.v}, m, 2);
      CHECK(two.b.f.data() == two.a.f.data());
      CHECK(two.b.f.cols() == two.a.f.cols());
    }
  }
}

}  // namespace

// The spring loops read and write the copies 64 bytes an instruction: a row that does not start
// on a cache line makes each access touch two (SPEED.md, *The copies on cache lines*).
TEST_CASE("copies: every row on a cache line, at a place in the page of its own") {
  check_layouts<double>();
  check_layouts<float>();
}
