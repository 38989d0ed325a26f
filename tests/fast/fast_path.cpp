// The fast engine (engine/fast/) against the lecture's path: the same numbers, bit for bit, on
// any number of threads and any block size; the runs layout describes exactly the springs of a
// set, and keeps doing so while tearing erases springs and plasticity changes rest lengths.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/guard.hpp"
#include "clothlab/core/threads.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/bending.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/local_global.hpp"
#include "clothlab/integrators/vbd.hpp"
#include "clothlab/integrators/xpbd.hpp"
#include "fast/aerodynamics.hpp"
#include "fast/engine.hpp"
#include "fast/springs.hpp"
#include "fast_util.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;
using clothlab::Matrix3X;
using test::engine_of;
using test::identical;
using test::run;

namespace {

// A cloth of rows x cols hanging from its top corners, with every effect that has a fast path,
// buoyancy (which has none: f goes back and forth between the layouts) among them, and `extra`
// tables. Its column springs form a run of 44 x 41 = 1804 springs.
std::string cloth(const std::string& extra, const std::string& method = "symplectic-euler",
                  Index rows = 45, Index cols = 41) {
  return test::hanging_cloth(rows, cols) + R"(
[aerodynamics]
wind = [3, 0, 2]
[drag]
area = 0.0004
[buoyancy]
volume = 1e-7
surface = -0.3
[ground]
y = -0.6
[integrator]
method = ")" +
         method + R"("
dt = 0.0005
duration = 1.0
)" + extra;
}

// Buoyancy taken out of cloth()'s scene: every effect left has a fast form, and an Euler step
// is one pass of the threads.
void no_buoyancy(clothlab::World& w) {
  std::erase_if(w.force_effects, [](const auto& e) { return e->name() == "buoyancy"; });
}

// A run of cloth()'s scene without buoyancy, every force summed by the fast engine, gives the
// state `expected` has, bit for bit.
void check_fast_state(const clothlab::World& fast, const clothlab::World& expected) {
  REQUIRE(engine_of(fast).plan().ends_with("drag+"));
  CHECK(fast.backend_evaluations == fast.force_evaluations);
  CHECK(identical(fast.particles.x, expected.particles.x));
  CHECK(identical(fast.particles.v, expected.particles.v));
  CHECK(identical(fast.particles.f, expected.particles.f));
}

clothlab::SpringDampers* spring_effect(clothlab::World& world, const char* name) {
  return clothlab::find_spring_effect(world, name);
}

std::set<std::pair<Index, Index>> pairs_of(const clothlab::SpringSet& s) {
  std::set<std::pair<Index, Index>> ends;
  for (size_t k = 0; k < s.size(); ++k)
    ends.insert({s.i(k), s.j(k)});
  return ends;
}

}  // namespace

TEST_CASE("fast path: runs cover every spring of a set once and in order") {
  clothlab::Scene scene = clothlab::parse_scene(cloth(""), "runs.toml");
  for (const char* name : {"springs", "bending"}) {
    const clothlab::SpringSet& s = spring_effect(scene.world, name)->springs();
    const std::vector<clothlab::fast::SpringRun> runs = clothlab::fast::spring_runs(s);
    size_t k = 0;
    for (const clothlab::fast::SpringRun& run : runs) {
      REQUIRE(run.k0 == k);
      for (Index t = 0; t < run.length; ++t, ++k) {
        CHECK(s.i(k) == run.i0 + t);
        CHECK(s.j(k) == run.j0 + t);
      }
    }
    CHECK(k == s.size());
    // A grid's families are long runs: the rows of each family (45 rows) and a few more, not
    // one run per spring. That is what makes the fast path fast.
    CHECK(runs.size() < 6 * 45);
    CHECK(s.size() >= 8 * runs.size());
  }
}

TEST_CASE("fast path: every change of a spring set's ends or constants moves its version") {
  clothlab::SpringSet s;
  const clothlab::Matrix3X x = clothlab::Matrix3X::Random(3, 4);
  const unsigned long empty = s.version();
  s.add_at_rest(0, 1, 10.0, 0.5, x);
  s.add_at_rest(1, 2, 10.0, 0.5, x);
  s.add_at_rest(2, 3, 10.0, 0.5, x);
  unsigned long seen = s.version();
  CHECK(seen != empty);
  // Each of these changes what a description of the set holds: each moves the version.
  const auto moves = [&](const std::string& what) {
    CAPTURE(what);
    CHECK(s.version() != seen);
    seen = s.version();
  };
  s.set_ks(1, 20.0);
  moves("set_ks");
  s.set_kd(0, 0.0);
  moves("set_kd");
  s.set_ends(2, 3, 2);
  moves("set_ends");
  s.reverse();
  moves("reverse");
  s.erase({0});
  moves("erase");
  // The rest lengths are no part of it: plasticity changes them every step.
  s.set_l0(0, 2.0);
  CHECK(s.version() == seen);
  CHECK(s.l0(0) == 2.0);
  // A copy is at the same version as the set it copies, and holds the same springs.
  const clothlab::SpringSet copy = s;
  CHECK(copy.version() == s.version());
  CHECK(copy.i() == s.i());
}

TEST_CASE("fast path: a run is uniform while its springs share ks and kd") {
  clothlab::Scene scene = clothlab::parse_scene(cloth(""), "runs.toml");
  clothlab::SpringSet& s = spring_effect(scene.world, "springs")->springs();
  std::vector<clothlab::fast::SpringRun> runs = clothlab::fast::spring_runs(s);
  // Each family is added with one ks and one kd: every run is uniform.
  CHECK(std::all_of(runs.begin(), runs.end(), [](const auto& r) { return r.uniform; }));
  // One spring in the middle of the fifth run gets its own kd; that run alone is not uniform.
  const clothlab::fast::SpringRun fifth = runs[4];
  REQUIRE(fifth.length > 2);
  s.set_kd(fifth.k0 + 1, 2.0 * s.kd(fifth.k0));
  // The third run's kd all 0, one of them -0: equal by ==, not bit for bit, and not uniform (a
  // product with -0 can round to a zero of the other sign).
  const clothlab::fast::SpringRun third = runs[2];
  for (Index t = 0; t < third.length; ++t)
    s.set_kd(third.k0 + static_cast<size_t>(t), 0.0);
  s.set_kd(third.k0 + 1, -0.0);
  runs = clothlab::fast::spring_runs(s);
  for (size_t r = 0; r < runs.size(); ++r) {
    CAPTURE(r);
    CHECK(runs[r].uniform == (r != 4 && r != 2));
  }
}

TEST_CASE("fast path: ks and kd changed in place between steps reach the forces") {
  // The runs layout keeps one ks and kd per uniform run; a change through the set (one spring
  // of a run, or every spring of another) must reach the next step, as on the readable path.
  const auto edit = [](clothlab::World& w) {
    clothlab::SpringSet& s = clothlab::find_spring_effect(w, "springs")->springs();
    const std::vector<clothlab::fast::SpringRun> runs = clothlab::fast::spring_runs(s);
    s.set_ks(runs[3].k0 + 5, 3.0 * s.ks(runs[3].k0 + 5));
    for (Index t = 0; t < runs.back().length; ++t)
      s.set_kd(runs.back().k0 + static_cast<size_t>(t), 0.5);
    clothlab::SpringSet& bending = clothlab::find_spring_effect(w, "bending")->springs();
    for (size_t k = 0; k < bending.size(); ++k)
      bending.set_ks(k, 4.0 * bending.ks(k));
  };
  for (int threads : {1, 2}) {
    CAPTURE(threads);
    std::vector<clothlab::Scene> scenes;
    for (bool fast : {false, true}) {
      clothlab::Scene scene = run(cloth(""), fast, threads, 40);
      edit(scene.world);
      for (int step = 0; step < 40; ++step)
        scene.world.step(scene.dt);
      scenes.push_back(std::move(scene));
    }
    const clothlab::World& readable = scenes[0].world;
    const clothlab::World& fast = scenes[1].world;
    CHECK(fast.backend_evaluations == fast.force_evaluations);
    CHECK(identical(fast.particles.x, readable.particles.x));
    CHECK(identical(fast.particles.v, readable.particles.v));
    // The edits changed the motion: without them the state differs.
    const clothlab::Scene unedited = run(cloth(""), true, threads, 80);
    CHECK_FALSE(identical(unedited.world.particles.x, fast.particles.x));
  }
}

TEST_CASE("fast path: springs edited between steps give the readable path's state, bit for bit") {
  // Each edit changes what the fast path has described (the springs' order, ends and constants)
  // while it is in use, as a lesson or a tool may: the set's version tells it, in every build.
  // Reversing the list in place and stepping on once gave the fast path a state 7.8 cm off. 60
  // steps after the edit are plenty: a fast path that kept its old runs differs at the first.
  using Edit = std::function<void(clothlab::SpringSet&)>;
  const std::vector<std::pair<const char*, Edit>> edits = {
      {"reverse", [](clothlab::SpringSet& s) { s.reverse(); }},
      {"remove every third",
       [](clothlab::SpringSet& s) {
         std::vector<size_t> gone;
         for (size_t k = 0; k < s.size(); k += 3)
           gone.push_back(k);
         s.erase(gone);
       }},
      {"turn half end for end",
       [](clothlab::SpringSet& s) {
         for (size_t k = 0; k < s.size() / 2; ++k)
           s.set_ends(k, s.j(k), s.i(k));
       }},
      {"ks", [](clothlab::SpringSet& s) { s.set_ks(s.size() / 2, 5.0 * s.ks(s.size() / 2)); }},
      {"kd", [](clothlab::SpringSet& s) { s.set_kd(7, 0.0); }},
      {"l0",
       [](clothlab::SpringSet& s) {
         for (size_t k = 0; k < s.size(); k += 5)
           s.set_l0(k, 1.1 * s.l0(k));
       }},
  };
  for (const auto& [name, edit] : edits) {
    const std::string what = name;
    CAPTURE(what);
    for (int threads : {1, 2}) {
      CAPTURE(threads);
      std::vector<clothlab::Scene> scenes;
      for (bool fast : {false, true}) {
        clothlab::Scene scene = run(cloth(""), fast, threads, 30);
        edit(spring_effect(scene.world, "springs")->springs());
        edit(spring_effect(scene.world, "bending")->springs());
        for (int step = 0; step < 60; ++step)
          scene.world.step(scene.dt);
        scenes.push_back(std::move(scene));
      }
      const clothlab::World& readable = scenes[0].world;
      const clothlab::World& fast = scenes[1].world;
      CHECK(fast.backend_evaluations > 0);
      CHECK(identical(fast.particles.x, readable.particles.x));
      CHECK(identical(fast.particles.v, readable.particles.v));
    }
  }
}

TEST_CASE("fast path: the builders' runs order keeps the same springs as the pairs listed") {
  const Index rows = 7, cols = 5;
  clothlab::Particles p;
  const clothlab::ClothGrid grid = clothlab::add_cloth(p, {rows, cols, 0.1, {}, false, 1.0});
  clothlab::SpringSet s;
  const std::vector<clothlab::IndexPair> pairs = clothlab::structural_pairs(rows, cols);
  clothlab::add_spring_family(s, pairs, grid.first, 10.0, 0.1, p.x);
  const std::set<std::pair<Index, Index>> expected(pairs.begin(), pairs.end());
  CHECK(pairs_of(s) == expected);
  CHECK(s.size() == pairs.size());
  // Every spring's rest length is the distance it was built at, whatever its place.
  for (size_t k = 0; k < s.size(); ++k)
    CHECK(s.l0(k) == doctest::Approx((p.x.col(s.j(k)) - p.x.col(s.i(k))).norm()));
  // Rows first (direction +1), then columns (+cols): one run per row, one for all columns.
  CHECK(clothlab::fast::spring_runs(s).size() == static_cast<size_t>(rows + 1));
}

TEST_CASE("fast path: the same state as the readable path, bit for bit, every integrator") {
  // Explicit Euler gains energy on undamped springs: few enough steps that it has not blown up.
  const std::vector<std::pair<std::string, int>> methods = {
      {"symplectic-euler", 150}, {"explicit-euler", 30}, {"rk4", 150}, {"velocity-verlet", 150}};
  for (const auto& [method, steps] : methods) {
    CAPTURE(method);
    const std::string text = cloth("", method);
    const clothlab::Scene readable = run(text, false, 1, steps);
    const clothlab::Scene fast = run(text, true, 1, steps);
    CHECK(identical(fast.world.particles.x, readable.world.particles.x));
    CHECK(identical(fast.world.particles.v, readable.world.particles.v));
    // The fast one did take the fast path, every evaluation; the readable one never did.
    CHECK(fast.world.backend_evaluations == fast.world.force_evaluations);
    CHECK(fast.world.backend_evaluations >= steps);
    CHECK(readable.world.backend_evaluations == 0);
    // The cloth moved: the test compares something.
    CHECK((fast.world.particles.x - clothlab::parse_scene(text, "t").world.particles.x)
              .cwiseAbs()
              .maxCoeff() > 1e-4);
  }
}

TEST_CASE("fast path: forces of one evaluation equal the readable path's, bit for bit") {
  clothlab::Scene scene = run(cloth(""), true, 1, 40);  // a state in motion
  const clothlab::World& w = scene.world;
  Matrix3X f_readable(3, w.particles.size()), f_fast(3, w.particles.size());
  w.compute_forces_readable(w.particles.x, w.particles.v, f_readable);
  w.compute_forces(w.particles.x, w.particles.v, f_fast);
  CHECK(identical(f_fast, f_readable));
}

namespace {

// A force without a fast path, for putting one between effects that have one: a weak pull of
// every particle toward the origin.
class PullToOrigin final : public clothlab::ForceEffect {
 public:
  std::string_view name() const override { return "pull"; }
  void add_forces(const clothlab::Particles& p, const Matrix3X& x, const Matrix3X& /*v*/,
                  Matrix3X& f) const override {
    for (Index i = 0; i < p.size(); ++i)
      f.col(i) -= 0.01 * x.col(i);
  }
};

}  // namespace

TEST_CASE("fast path: effects without a fast path, between and after those with one") {
  // The scene's own order puts buoyancy (no fast path) last; the pull goes in after the
  // springs, so f moves to the engine's layout and back twice within one evaluation.
  const std::string text = cloth("");
  for (int threads : {1, 2}) {
    CAPTURE(threads);
    const auto add_pull = [](clothlab::World& w) {
      w.force_effects.insert(w.force_effects.begin() + 1, std::make_unique<PullToOrigin>());
    };
    const clothlab::Scene readable_scene = run(text, false, threads, 100, add_pull);
    const clothlab::Scene fast_scene = run(text, true, threads, 100, add_pull);
    const clothlab::World& readable = readable_scene.world;
    const clothlab::World& fast = fast_scene.world;
    // Which effects the fast engine summed itself, in the world's order.
    CHECK(engine_of(fast).plan() ==
          "springs+ pull- bending+ damping+ gravity+ aerodynamics+ drag+ buoyancy-");
    CHECK(fast.backend_evaluations == fast.force_evaluations);
    CHECK(identical(fast.particles.x, readable.particles.x));
    CHECK(identical(fast.particles.v, readable.particles.v));
    // Buoyancy acts: part of the cloth is below its surface.
    CHECK(fast.particles.x.row(1).minCoeff() < -0.3);
  }
}

TEST_CASE("fast path: an effect replaced between steps is never summed as the one it replaced") {
  // Damping is destroyed and a pull made in its place, likely at the same address (the same
  // small allocation): the fast engine must see a new effect, of another type, and leave it to
  // its add_forces, as the lecture's path does.
  const auto replace_damping = [](clothlab::World& w) {
    for (auto& effect : w.force_effects) {
      if (effect->name() != "damping") continue;
      effect.reset();
      effect = std::make_unique<PullToOrigin>();
    }
  };
  std::vector<clothlab::Scene> scenes;
  for (bool fast : {false, true}) {
    clothlab::Scene scene = run(cloth(""), fast, 1, 20);
    replace_damping(scene.world);
    for (int step = 0; step < 40; ++step)
      scene.world.step(scene.dt);
    scenes.push_back(std::move(scene));
  }
  CHECK(engine_of(scenes[1].world).plan().find("pull-") != std::string::npos);
  CHECK(identical(scenes[1].world.particles.x, scenes[0].world.particles.x));
  CHECK(identical(scenes[1].world.particles.v, scenes[0].world.particles.v));
}

TEST_CASE("fast path: the Euler methods move particles in the pass that sums their forces") {
  // Without buoyancy the last effect has a fast path, so each thread copies its particles'
  // forces back and moves them, 512 at a time, in the pass that summed the forces
  // (FastEngine::step). 45 x 41 cloth: ranges and chunks end mid-row.
  for (const char* method : {"symplectic-euler", "explicit-euler"}) {
    for (int threads : {1, 2, 3}) {
      CAPTURE(method);
      CAPTURE(threads);
      const clothlab::Scene readable_scene =
          run(cloth("", method), false, threads, 30, no_buoyancy);
      const clothlab::Scene fast_scene = run(cloth("", method), true, threads, 30, no_buoyancy);
      const clothlab::World& readable = readable_scene.world;
      const clothlab::World& fast = fast_scene.world;
      REQUIRE(engine_of(fast).plan().ends_with("drag+"));
      CHECK(fast.backend_evaluations == fast.force_evaluations);
      CHECK(identical(fast.particles.x, readable.particles.x));
      CHECK(identical(fast.particles.v, readable.particles.v));
      CHECK(identical(fast.particles.f, readable.particles.f));
      // The cloth moved: the test compares something.
      CHECK((fast.particles.v.cwiseAbs().maxCoeff()) > 1e-3);
    }
  }
}

TEST_CASE("fast path: blocks of any size give the readable state bit for bit") {
  // A step's one pass takes each thread's particles pass_block at a time through every effect,
  // then moves them (fast/engine.cpp): springs across a block's border are evaluated on both
  // sides. Blocks of one particle, shorter than a row, ending mid-row and mid-chunk, and larger
  // than the cloth; with a ground and a sphere riding along (the cloth starts through both).
  const std::string text = cloth("[sphere]\ncentre = [0.4, -0.45, 0.0]\nradius = 0.08\n");
  const clothlab::Scene readable = run(text, false, 1, 40, no_buoyancy);
  CHECK(readable.world.particles.x.row(1).minCoeff() == -0.6);  // particles lie on the ground
  for (const Index block : {Index{1}, Index{29}, Index{600}, Index{1000}, Index{100000}}) {
    for (int threads : {1, 2}) {
      CAPTURE(block);
      CAPTURE(threads);
      const clothlab::Scene fast = run(text, true, threads, 40, [&](clothlab::World& w) {
        no_buoyancy(w);
        engine_of(w).pass_block = block;
      });
      check_fast_state(fast.world, readable.world);
    }
  }
}

TEST_CASE("fast path: moving pins and gusts give the readable state bit for bit") {
  // The cloth waved by one top corner while the other turns on a circle, in gusts on its
  // triangles and on each particle: the effects read the wind of the step's start time on
  // both paths, and the pins are placed after the ground (which rides along in the fast pass).
  std::string text = cloth(R"(
[[cloth.pin_path]]
pins = [0]
times = [0, 0.02, 0.05]
offsets = [[0, 0, 0], [0.05, 0, 0.1], [0, 0.02, 0]]
[[cloth.pin_path]]
pins = [40]
centre = [0.7, 0.1, 0]
axis = [1, 0, 1]
period = 0.1
)");
  const auto with = [&](const std::string& old_line, const std::string& new_lines) {
    text.replace(text.find(old_line), old_line.size(), new_lines);
  };
  with("wind = [3, 0, 2]", "wind = [3, 0, 2]\ngust = [0, 1, 4]\ngust_period = 0.03");
  with("area = 0.0004",
       "area = 0.0004\nwind_times = [0, 0.04]\nwind_values = [[0, 0, 0], [-2, 1, 5]]");
  for (const std::string method : {"symplectic-euler", "rk4"}) {
    for (int threads : {1, 2}) {
      CAPTURE(method);
      CAPTURE(threads);
      std::string scene_text = text;
      scene_text.replace(scene_text.find("symplectic-euler"), 16, method);
      const clothlab::Scene readable = run(scene_text, false, threads, 100);
      const clothlab::Scene fast = run(scene_text, true, threads, 100);
      CHECK(fast.world.backend_evaluations == fast.world.force_evaluations);
      CHECK(fast.world.backend_evaluations >= 100);
      CHECK(identical(fast.world.particles.x, readable.world.particles.x));
      CHECK(identical(fast.world.particles.v, readable.world.particles.v));
      // The pins did move, and the wind did change.
      CHECK(fast.world.particles.v.col(40).norm() > 1.0);
      const auto* aero = test::find_force_effect<clothlab::Aerodynamics>(fast.world);
      REQUIRE(aero != nullptr);
      CHECK((aero->wind() - clothlab::Vec3(3, 0, 2)).norm() > 0.1);
    }
  }
}

TEST_CASE("fast path: 2, 3 and 4 threads give the 1-thread state bit for bit") {
  const std::string text = cloth("");
  const clothlab::Scene one = run(text, true, 1, 150);
  for (int threads : {2, 3, 4}) {
    CAPTURE(threads);
    const clothlab::Scene many = run(text, true, threads, 150);
    CHECK(identical(many.world.particles.x, one.world.particles.x));
    CHECK(identical(many.world.particles.v, one.world.particles.v));
  }
  // More threads than some runs have springs.
  const std::string small = cloth("", "symplectic-euler", 9, 7);
  CHECK(identical(run(small, true, 4, 50).world.particles.x,
                  run(small, false, 1, 50).world.particles.x));
}

TEST_CASE("fast path: any split of the particles between threads gives the 1-thread state") {
  // The fast engine's passes move the split of the particles between the threads toward the
  // busier thread's side (World::for_particles_with_barrier), so a step may take any split.
  // Here a new one before every step, drawn at random: pieces empty, of one particle, and
  // bounds off any multiple of 16; on a cloth through a ground and a sphere, which ride along.
  const std::string text = cloth("[sphere]\ncentre = [0.4, -0.45, 0.0]\nradius = 0.08\n");
  const clothlab::Scene one = run(text, true, 1, 60, no_buoyancy);
  for (int threads : {2, 3}) {
    CAPTURE(threads);
    clothlab::Scene scene = clothlab::parse_scene(text, "fast-path.toml");
    no_buoyancy(scene.world);
    scene.world.threads = threads;
    const Index n = scene.world.particles.size();
    std::mt19937 random(7);
    std::uniform_int_distribution<Index> anywhere(0, n);
    for (int s = 0; s < 60; ++s) {
      std::vector<Index> bounds{0, n};
      for (int t = 1; t < threads; ++t)
        bounds.insert(bounds.end() - 1,
                      s % 10 == 0 ? Index{s % 20 == 0 ? 0 : 1} : anywhere(random));
      std::sort(bounds.begin(), bounds.end());
      scene.world.set_particle_bounds(bounds);
      scene.world.step(scene.dt);
    }
    check_fast_state(scene.world, one.world);
  }
}

TEST_CASE("fast path: the world's passes take the split it keeps, and it stays a split") {
  clothlab::Scene scene = clothlab::parse_scene(cloth(""), "fast-path.toml");
  clothlab::World& world = scene.world;
  const Index n = world.particles.size();
  world.threads = 3;
  CHECK(world.particle_bounds() == clothlab::even_bounds(n, 3));
  world.set_particle_bounds({0, 5, 37, n});
  std::vector<std::pair<Index, Index>> pieces(3), with_barrier(3);
  std::vector<std::atomic<int>> calls(3);
  world.for_particles([&](Index begin, Index end) {
    const size_t t = begin == 0 ? 0 : begin == 5 ? 1 : 2;
    pieces[t] = {begin, end};
    ++calls[t];
  });
  CHECK(pieces == std::vector<std::pair<Index, Index>>{{0, 5}, {5, 37}, {37, n}});
  // Not a split of the particles: refused, and the one kept stays.
  for (const std::vector<Index>& bad : std::vector<std::vector<Index>>{
           {0, 5, n}, {1, 5, 37, n}, {0, 37, 5, n}, {0, 5, 37, n + 1}, {0, 5, 37, n - 1}}) {
    CHECK_THROWS_AS(world.set_particle_bounds(bad), std::invalid_argument);
  }
  CHECK(world.particle_bounds()[1] == 5);
  world.for_particles_with_barrier([&](Index begin, Index end, const clothlab::Barrier& barrier) {
    barrier.wait();
    const size_t t = begin == 0 ? 0 : begin == 5 ? 1 : 2;
    with_barrier[t] = {begin, end};
    ++calls[t];
  });
  CHECK(with_barrier == pieces);  // (its pass may have moved the split since, for the next)
  for (const auto& count : calls)
    CHECK(count == 2);
  // After steps whose passes may have moved it, still a split; another count of threads starts
  // from the even one.
  for (int s = 0; s < 30; ++s)
    world.step(scene.dt);
  const std::vector<Index>& after = world.particle_bounds();
  REQUIRE(after.size() == 4);
  CHECK(after.front() == 0);
  CHECK(after.back() == n);
  CHECK(std::is_sorted(after.begin(), after.end()));
  world.threads = 2;
  CHECK(world.particle_bounds() == clothlab::even_bounds(n, 2));
}

TEST_CASE("fast path: balance_bounds gives the costlier piece fewer items, a step at a time") {
  using clothlab::balance_bounds;
  using Bounds = std::vector<Index>;
  // Within the tolerance, or with no time measured, nothing moves.
  Bounds b{0, 1000, 2000};
  CHECK_FALSE(balance_bounds(b, {1.0, 1.02}, 16, 1000, 0.03));
  CHECK_FALSE(balance_bounds(b, {0.0, 0.0}, 16, 1000, 0.03));
  CHECK_FALSE(balance_bounds(b, {std::nan(""), 1.0}, 16, 1000, 0.03));
  CHECK_FALSE(balance_bounds(b, {-1.0, 1.0}, 16, 1000, 0.03));
  CHECK(b == Bounds{0, 1000, 2000});
  // Piece 0's items cost 3 times piece 1's: the costs even out at 1000 x 2 / 3 = 666.7; the bound
  // goes half way there, 833.3, onto a multiple of 16.
  CHECK(balance_bounds(b, {3.0, 1.0}, 16, 1000, 0.03));
  CHECK(b == Bounds{0, 832, 2000});
  // At most max_shift a call (then onto the nearest multiple of 16).
  b = {0, 1000, 2000};
  CHECK(balance_bounds(b, {3.0, 1.0}, 16, 64, 0.03));
  CHECK(b == Bounds{0, 944, 2000});
  // Three pieces, the first's items 4 times as costly: the costs even out at 300 x 1 / 2 = 150
  // and at 300 (the first piece's end, as measured); each bound goes half way from where it was.
  b = {0, 300, 600, 900};
  CHECK(balance_bounds(b, {1200.0, 300.0, 300.0}, 1, 1000, 0.03));
  CHECK(b == Bounds{0, 225, 450, 900});
  // An empty piece gets items back.
  b = {0, 0, 100};
  CHECK(balance_bounds(b, {0.0, 1.0}, 16, 1000, 0.03));
  CHECK(b == Bounds{0, 32, 100});
  // Repeated, as passes do, on items whose cost does not change: three pieces, the last third of
  // the items 4 times as costly. The pieces' work ends within the tolerance of the mean.
  const auto cost = [](Index i) { return i < 600 ? 1.0 : 4.0; };
  const auto work_of = [&](const Bounds& bounds) {
    std::vector<double> work(bounds.size() - 1, 0.0);
    for (size_t t = 0; t + 1 < bounds.size(); ++t)
      for (Index i = bounds[t]; i < bounds[t + 1]; ++i)
        work[t] += cost(i);
    return work;
  };
  b = clothlab::even_bounds(900, 3);
  int moves = 0;
  while (balance_bounds(b, work_of(b), 1, 20, 0.03))
    REQUIRE(++moves < 100);
  CHECK(moves > 5);
  const std::vector<double> work = work_of(b);
  CHECK(*std::max_element(work.begin(), work.end()) <= 1.03 * 1800.0 / 3.0);
  CHECK(b.front() == 0);
  CHECK(b.back() == 900);
  CHECK(std::is_sorted(b.begin(), b.end()));
}

TEST_CASE("fast path: runs just below, at and above the gap where forces skip the buffer") {
  // A cloth `cols` wide has column springs cols particles apart, diagonals cols - 1 and
  // cols + 1, column bending 2 cols: around kDirectGap, the runs of one cloth take both ways
  // (fast/springs.cpp), and a particle gets shares from both in one evaluation.
  const Index gap = clothlab::fast::kDirectGap;
  for (Index cols : {gap - 1, gap, gap + 1}) {
    const std::string text = cloth("", "symplectic-euler", 12, cols);
    const clothlab::Scene readable = run(text, false, 1, 80);
    for (int threads : {1, 3}) {
      CAPTURE(cols);
      CAPTURE(threads);
      const clothlab::Scene fast = run(text, true, threads, 80);
      CHECK(fast.world.backend_evaluations == fast.world.force_evaluations);
      CHECK(identical(fast.world.particles.x, readable.world.particles.x));
      CHECK(identical(fast.world.particles.v, readable.world.particles.v));
    }
  }
}

TEST_CASE("fast path: tearing and plasticity on the runs layout match the readable path") {
  // A storm that stretches the sheet past its yield and tearing limits.
  const std::string text =
      cloth("[plasticity]\nyield_strain = 0.02\nmax_strain = 0.4\n[tearing]\nstrain = 0.08\n",
            "symplectic-euler", 24, 24);
  std::string stormy = text;
  stormy.replace(stormy.find("wind = [3, 0, 2]"), 16, "wind = [0, 0, 60]");
  clothlab::Scene readable = run(stormy, false, 1, 1500);
  clothlab::Scene fast = run(stormy, true, 1, 1500);
  clothlab::Scene threaded = run(stormy, true, 2, 1500);
  clothlab::Scene built = clothlab::parse_scene(stormy, "t");
  const clothlab::SpringSet& s = spring_effect(fast.world, "springs")->springs();
  const clothlab::SpringSet& r = spring_effect(readable.world, "springs")->springs();
  REQUIRE(s.size() < spring_effect(built.world, "springs")->springs().size());  // springs tore
  CHECK(identical(fast.world.particles.x, readable.world.particles.x));
  CHECK(identical(threaded.world.particles.x, readable.world.particles.x));
  CHECK(s.l0() == r.l0());  // plastic flow, spring by spring
  CHECK(pairs_of(s) == pairs_of(r));
}

TEST_CASE("fast path: the springs' potential energy is the readable path's, bit for bit") {
  // The guard's energy check sums it every 32 steps. The engine room computes the springs'
  // energies run by run, several at once, each thread those of its range of the set (runs cut
  // where the ranges meet), and adds them up in the set's order: the same bits on 1 to 4 threads.
  std::string torn = cloth(
      "[plasticity]\nyield_strain = 0.02\nmax_strain = 0.4\n[tearing]\n"
      "strain = 0.08\n",
      "symplectic-euler", 24, 24);
  torn.replace(torn.find("wind = [3, 0, 2]"), 16, "wind = [0, 0, 60]");
  // Each scene, its steps, and how many of its spring sets the engine room takes: sets whose
  // runs are too short to pay (a 9 x 7 cloth's springs; both sets of the cloth the storm tore)
  // are left to the effect's own loop, as their forces are.
  struct Case {
    std::string text;
    int steps;
    int taken;
  };
  // The 60 x 60 cloth's 20,000 springs make five blocks of the sum (kEnergyBlock), which the
  // threads' ranges cut; the 100 x 100 cloth's two sets (39,402 and 19,600 springs) ten and
  // five, summed eight, four, two and one at a time, each set's last block short.
  const std::vector<Case> scenes = {{cloth(""), 150, 2},
                                    {torn, 1500, 0},
                                    {cloth("", "symplectic-euler", 9, 7), 50, 1},
                                    {cloth("", "symplectic-euler", 60, 60), 20, 2},
                                    {cloth("", "symplectic-euler", 100, 100), 20, 2}};
  const auto bits = [](double a) { return std::bit_cast<std::uint64_t>(a); };
  for (const auto& [text, steps, expected] : scenes) {
    CAPTURE(text);
    clothlab::Scene scene = run(text, true, 1, steps);
    clothlab::World& world = scene.world;
    int taken = 0;
    for (const auto& effect : world.force_effects) {
      CAPTURE(effect->name());
      const double own = effect->potential_energy(world.particles, world.particles.x);
      double fast = 0.0;
      if (!world.backend->potential_energy(world, *effect, world.particles.x, fast)) continue;
      ++taken;
      CHECK(own > 0.0);  // the springs are stretched: the test compares something
      CHECK(bits(fast) == bits(own));
      for (int threads : {2, 3, 4}) {
        CAPTURE(threads);
        world.threads = threads;
        double threaded = 0.0;
        CHECK(world.backend->potential_energy(world, *effect, world.particles.x, threaded));
        CHECK(bits(threaded) == bits(own));
      }
      world.threads = 1;
    }
    CHECK(taken == expected);
    // The world's sum, with the backend and without it.
    const double with_backend = world.potential_energy();
    const std::unique_ptr<clothlab::Backend> backend = std::move(world.backend);
    CHECK(bits(world.potential_energy()) == bits(with_backend));
  }
  // An effect that is not the world's own is declined.
  clothlab::Scene other = run(cloth(""), true, 1, 1);
  clothlab::Scene scene = run(cloth(""), true, 1, 1);
  double energy = -1.0;
  CHECK_FALSE(scene.world.backend->potential_energy(scene.world, *other.world.force_effects[0],
                                                    scene.world.particles.x, energy));
  CHECK(energy == -1.0);
}

TEST_CASE("fast path: a grid's triangles form one run per row, two triangles a cell") {
  const Index rows = 5, cols = 12;  // runs of 11 cells: long enough to be worth one
  const clothlab::Scene scene =
      clothlab::parse_scene(cloth("", "symplectic-euler", rows, cols), "t");
  const auto* aero = test::find_force_effect<clothlab::Aerodynamics>(scene.world);
  REQUIRE(aero != nullptr);
  const auto groups = clothlab::fast::triangle_groups(aero->triangles());
  REQUIRE(groups.size() == rows - 1);
  size_t next = 0;
  for (const auto& g : groups) {
    CHECK(g.run);
    CHECK(g.k0 == next);  // in order, each triangle once
    CHECK(g.period == 2);
    CHECK(g.length == cols - 1);
    next += g.size;
  }
  CHECK(next == aero->triangles().size());
  // Cell p has triangles (p, p + cols, p + 1) then (p + cols, p + cols + 1, p + 1): particle q
  // gets its shares from (phase, corner) (1, 1), (0, 1), (1, 0), (0, 2), (1, 2), (0, 0), in the
  // list's order (the triangles are q - cols - 1, q - cols, q - cols, q - 1, q - 1 and q).
  const std::array<std::array<int, 2>, 6> order = {
      {{1, 1}, {0, 1}, {1, 0}, {0, 2}, {1, 2}, {0, 0}}};
  CHECK(groups[0].order == order);
}

TEST_CASE("fast path: triangles in other orders give the readable result") {
  // The grid's triangles listed backwards (no runs: one by one), a row's first triangles before
  // its second ones (runs of one phase), and shuffled, on 1 and 3 threads.
  const std::string text = cloth("", "symplectic-euler", 12, 20);
  for (const char* order : {"backwards", "by phase", "shuffled"}) {
    for (int threads : {1, 3}) {
      CAPTURE(order);
      CAPTURE(threads);
      std::vector<clothlab::Scene> scenes;
      for (bool fast : {false, true}) {
        clothlab::Scene scene = clothlab::parse_scene(text, "fast-path.toml");
        for (auto& effect : scene.world.force_effects) {
          const auto* aero = dynamic_cast<const clothlab::Aerodynamics*>(effect.get());
          if (!aero) continue;
          std::vector<clothlab::Triangle> t = aero->triangles();
          if (std::string(order) == "backwards") {
            std::reverse(t.begin(), t.end());
          } else if (std::string(order) == "by phase") {
            std::stable_partition(t.begin(), t.end(),
                                  [](const auto& tri) { return tri[2] == tri[0] + 1; });
          } else {
            std::mt19937 random(7);
            std::shuffle(t.begin(), t.end(), random);
          }
          effect =
              std::make_unique<clothlab::Aerodynamics>(t, clothlab::kAirDensity, 1.2, aero->wind());
        }
        if (!fast) scene.world.backend.reset();
        scene.world.threads = threads;
        for (int step = 0; step < 60; ++step)
          scene.world.step(scene.dt);
        scenes.push_back(std::move(scene));
      }
      CHECK(scenes[1].world.backend_evaluations == scenes[1].world.force_evaluations);
      CHECK(identical(scenes[1].world.particles.x, scenes[0].world.particles.x));
      CHECK(identical(scenes[1].world.particles.v, scenes[0].world.particles.v));
    }
  }
}

TEST_CASE("fast path: a set changed in place, or with no runs, still gives the readable result") {
  const std::string text = cloth("", "symplectic-euler", 20, 20);
  clothlab::Scene fast = clothlab::parse_scene(text, "a.toml");
  clothlab::Scene readable = clothlab::parse_scene(text, "b.toml");
  readable.world.backend.reset();
  fast.world.threads = 2;
  // Shuffle the springs and flip every other one. The set forms no runs any more: the fast path
  // hands it to add_forces, which sums in the new order.
  for (clothlab::World* w : {&fast.world, &readable.world}) {
    clothlab::SpringSet& s = spring_effect(*w, "springs")->springs();
    std::vector<size_t> order(s.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::shuffle(order.begin(), order.end(), std::mt19937(7));
    clothlab::SpringSet out;
    for (size_t k : order)
      out.add(s.i(k), s.j(k), s.ks(k), s.kd(k), s.l0(k));
    s = out;
    for (size_t k = 0; k < s.size(); k += 2)
      s.set_ends(k, s.j(k), s.i(k));
    CHECK(clothlab::fast::spring_runs(s).size() > s.size() / 2);
  }
  for (int step = 0; step < 100; ++step) {
    fast.world.step(fast.dt);
    readable.world.step(readable.dt);
  }
  CHECK(identical(fast.world.particles.x, readable.world.particles.x));
}

TEST_CASE("fast path: springs listed from their higher-numbered end match the readable path") {
  // Every spring flipped: the runs are as long as before, but i0 > j0, so the i ends are the
  // upper ends and take their shares first.
  const std::string text = cloth("", "symplectic-euler", 20, 20);
  clothlab::Scene fast = clothlab::parse_scene(text, "a.toml");
  clothlab::Scene readable = clothlab::parse_scene(text, "b.toml");
  readable.world.backend.reset();
  for (clothlab::World* w : {&fast.world, &readable.world}) {
    for (const char* name : {"springs", "bending"}) {
      clothlab::SpringSet& s = spring_effect(*w, name)->springs();
      for (size_t k = 0; k < s.size(); ++k)
        s.set_ends(k, s.j(k), s.i(k));
      const std::vector<clothlab::fast::SpringRun> runs = clothlab::fast::spring_runs(s);
      CHECK(s.size() >= 8 * runs.size());
      CHECK(runs.front().i0 > runs.front().j0);
    }
  }
  for (int step = 0; step < 100; ++step) {
    fast.world.step(fast.dt);
    readable.world.step(readable.dt);
  }
  CHECK(fast.world.backend_evaluations == 100);
  CHECK(identical(fast.world.particles.x, readable.world.particles.x));
  CHECK(identical(fast.world.particles.v, readable.world.particles.v));
}

namespace {

// The scene stepped `steps` times on the lecture's path alone: every post-step effect in a pass
// of its own after the integrator, the guard's checks in passes of their own.
clothlab::Scene run_in_separate_passes(const std::string& text, int steps,
                                       const std::function<void(clothlab::World&)>& edit = {}) {
  clothlab::Scene scene = clothlab::parse_scene(text, "fast-path.toml");
  if (edit) edit(scene.world);
  scene.world.backend.reset();
  for (int s = 0; s < steps; ++s)
    scene.world.step(scene.dt);
  return scene;
}

// A post-step effect that acts on each particle alone (a small push along x for any particle
// below y = -0.3), as a ground does, but one the fast engine does not know: it counts its calls.
class PushLowParticles final : public clothlab::PostStepEffect {
 public:
  long wholes = 0;
  std::string_view name() const override { return "push"; }
  void apply(clothlab::World& world, const clothlab::StepTime& time) override {
    ++wholes;
    clothlab::Particles& p = world.particles;
    for (Index i = 0; i < p.size(); ++i)
      if (p.x(1, i) < -0.3 && p.inv_m[i] > 0.0) p.v(0, i) += 0.5 * time.h;
  }
};

// A post-step effect that reads the whole state: the lowest height of any particle, each step.
class RecordLowest final : public clothlab::PostStepEffect {
 public:
  std::vector<double> lowest;
  std::string_view name() const override { return "record"; }
  void apply(clothlab::World& world, const clothlab::StepTime& /*time*/) override {
    lowest.push_back(world.particles.x.row(1).minCoeff());
  }
};

}  // namespace

TEST_CASE(
    "fast path: a ground and a sphere in the step's one pass give the state of passes "
    "of their own") {
  // The cloth hangs from y = 0 to y = -0.88: its lower rows start below the ground (y = -0.6)
  // and some particles inside the sphere, so both push particles out from the first step.
  const std::string sphere = "[sphere]\ncentre = [0.4, -0.45, 0.0]\nradius = 0.08\n";
  // With buoyancy last (no fast path) the particles move after the forces' pass, without it in
  // that pass; the Euler methods move in one pass either way, RK4 does not.
  for (const char* method : {"symplectic-euler", "explicit-euler", "rk4"}) {
    for (bool buoyancy : {true, false}) {
      const std::string text = cloth(sphere, method);
      const auto edit = buoyancy ? std::function<void(clothlab::World&)>{} : no_buoyancy;
      const clothlab::Scene separate = run_in_separate_passes(text, 30, edit);
      const clothlab::World& want = separate.world;
      REQUIRE(want.post_step_effects.size() == 2);
      CHECK(want.particles.x.row(1).minCoeff() == -0.6);  // particles lie on the ground
      const clothlab::Vec3 centre(0.4, -0.45, 0.0);
      const double nearest = (want.particles.x.colwise() - centre).colwise().norm().minCoeff();
      CHECK(nearest == doctest::Approx(0.08).epsilon(1e-9));  // and on the sphere
      for (bool fast : {true, false}) {
        for (int threads : {1, 2, 3}) {
          CAPTURE(method);
          CAPTURE(buoyancy);
          CAPTURE(fast);
          CAPTURE(threads);
          const clothlab::Scene one_pass = run(text, fast, threads, 30, edit);
          CHECK(identical(one_pass.world.particles.x, want.particles.x));
          CHECK(identical(one_pass.world.particles.v, want.particles.v));
        }
      }
    }
  }
}

TEST_CASE(
    "fast path: only a ground and a sphere that lead the post-step list go into the step's "
    "pass") {
  // An effect the fast engine does not know is applied whole, after the pass, each step; the
  // ground behind it waits for it, and the state is the lecture's path's.
  const std::string text = cloth("");
  for (int threads : {1, 2}) {
    CAPTURE(threads);
    PushLowParticles* push = nullptr;
    const auto push_first = [&](clothlab::World& w) {
      auto effect = std::make_unique<PushLowParticles>();
      push = effect.get();
      w.post_step_effects.insert(w.post_step_effects.begin(), std::move(effect));
    };
    const clothlab::Scene one_pass = run(text, true, threads, 40, push_first);
    CHECK(push->wholes == 40);
    CHECK(one_pass.world.backend_evaluations == 40);
    const clothlab::Scene separate = run_in_separate_passes(text, 40, push_first);
    CHECK(push->wholes == 40);
    CHECK(identical(one_pass.world.particles.x, separate.world.particles.x));
    CHECK(identical(one_pass.world.particles.v, separate.world.particles.v));
  }
  // The ground leading the list rides along: --stats finds no time of its own for it, where
  // the lecture's path times its pass.
  for (bool fast : {true, false}) {
    CAPTURE(fast);
    clothlab::Scene scene = clothlab::parse_scene(text, "fast-path.toml");
    if (!fast) scene.world.backend.reset();
    clothlab::StepTimer timer;
    timer.attach(scene.world);
    const clothlab::StepTimes& times = timer.times;
    for (int step = 0; step < 20; ++step)
      scene.world.step(scene.dt);
    REQUIRE(scene.world.post_step_effects.front()->name() == "ground");
    const double ground = times.post_step_effects.empty() ? 0.0 : times.post_step_effects.front();
    CHECK((ground == 0.0) == fast);
    CHECK((times.backend_steps > 0.0) == fast);
  }
  // Behind an effect that reads the whole state, the ground waits until the step has moved
  // every particle and that effect has seen them: the lowest heights it records come from
  // before the ground lifts anything, as in passes of their own.
  RecordLowest* record = nullptr;
  const auto record_first = [&](clothlab::World& w) {
    auto effect = std::make_unique<RecordLowest>();
    record = effect.get();
    w.post_step_effects.insert(w.post_step_effects.begin(), std::move(effect));
  };
  const clothlab::Scene separate = run_in_separate_passes(text, 40, record_first);
  const std::vector<double> want = record->lowest;
  REQUIRE(want.size() == 40);
  CHECK(want.front() < -0.6);  // below the ground when recorded
  const clothlab::Scene one_pass = run(text, true, 2, 40, record_first);
  CHECK(record->lowest == want);
  CHECK(identical(one_pass.world.particles.x, separate.world.particles.x));
}

TEST_CASE("fast path: a thread team runs every job once and passes on what a job throws") {
  clothlab::ThreadTeam team(3);
  std::atomic<int> sum{0};
  for (int round = 0; round < 100; ++round)
    team.run([&](int t) { sum += t + 1; });
  CHECK(sum == 100 * (1 + 2 + 3));
  CHECK_THROWS_AS(team.run([](int t) {
    if (t == 2) throw std::runtime_error("a stub");
  }),
                  std::runtime_error);
  team.run([&](int t) { sum += t; });  // still usable
  CHECK(sum == 100 * 6 + 3);
}

TEST_CASE(
    "fast path: a job's threads meet at sync(), last() runs once there, and a throw leaves none "
    "waiting") {
  for (int size = 1; size <= 4; ++size) {
    CAPTURE(size);
    clothlab::ThreadTeam team(size);
    // Each thread writes its slot, then, past the barrier, reads every slot: it must find what
    // every other thread wrote in this round, never the last round's value.
    std::vector<long> slots(static_cast<size_t>(size), -1);
    std::atomic<long> stale{0};
    constexpr long kRounds = 300;
    for (long round = 0; round < kRounds; ++round) {
      team.run([&](int t) {
        slots[static_cast<size_t>(t)] = round * 10 + t;
        team.sync();
        for (int u = 0; u < size; ++u)
          stale += slots[static_cast<size_t>(u)] != round * 10 + u;
        team.sync();  // a second meeting in the same job
      });
    }
    CHECK(stale == 0);
    CHECK(team.runs() == kRounds);  // two meetings a job, no more wakes
    // sync(last): last() runs once a meeting, on the thread that arrives last (after every
    // thread's first part), and before any thread leaves: each finds its count moved on.
    long lasts = 0;
    std::atomic<long> early{0}, late{0};
    std::vector<long> parts(static_cast<size_t>(size), 0);
    const std::function<void()> last = [&] {
      for (int u = 0; u < size; ++u)
        late += parts[static_cast<size_t>(u)] != lasts + 1;  // a thread not yet done
      ++lasts;
    };
    for (long round = 0; round < kRounds; ++round) {
      team.run([&](int t) {
        for (long meeting = 0; meeting < 3; ++meeting) {
          ++parts[static_cast<size_t>(t)];
          team.sync(last);
          early += lasts != 3 * round + meeting + 1;
        }
      });
    }
    CHECK(lasts == 3 * kRounds);
    CHECK(early == 0);
    CHECK(late == 0);
    // A job that throws on one thread before the barrier, the others waiting there: run()
    // returns and rethrows that error, and the team still works.
    for (int thrower = 0; thrower < size; ++thrower) {
      CAPTURE(thrower);
      CHECK_THROWS_WITH_AS(team.run([&](int t) {
        if (t == thrower) throw std::runtime_error("the first part failed");
        team.sync();
        team.sync();
      }),
                           "the first part failed", std::runtime_error);
      std::atomic<int> met{0};
      team.run([&](int) {
        team.sync();
        ++met;
      });
      CHECK(met == size);
    }
    // last() that throws: the job's error, the others released, the team still works.
    const std::function<void()> failing = [] { throw std::runtime_error("between the parts"); };
    std::atomic<int> past{0};
    CHECK_THROWS_WITH_AS(team.run([&](int) {
      team.sync(failing);
      ++past;
    }),
                         "between the parts", std::runtime_error);
    CHECK(past == 0);
    std::atomic<int> met{0};
    team.run([&](int) {
      team.sync(last);
      ++met;
    });
    CHECK(met == size);
  }
}

TEST_CASE("fast path: an Euler step wakes the threads once, and so does a force sum") {
  // The copy into the fast layout and the pass that sums and moves are one job of the threads,
  // with a barrier inside it (FastEngine::pass): each step wakes them once, and the guard's
  // energy check (every 32 steps) once more, for the springs' energies. Buoyancy (no fast
  // form) is taken out, so that every effect has one; the ground rides along in the pass.
  for (const char* method : {"symplectic-euler", "explicit-euler"}) {
    for (int threads : {2, 3}) {
      CAPTURE(method);
      CAPTURE(threads);
      clothlab::Scene scene = run(cloth("", method), true, threads, 1, no_buoyancy);
      REQUIRE(engine_of(scene.world).plan().ends_with("drag+"));
      constexpr int kSteps = 40;  // past an energy check
      const long checks = test::energy_check_wakes(scene.world, scene.world.steps, kSteps);
      const long before = scene.world.thread_wakes();
      for (int s = 0; s < kSteps; ++s)
        scene.world.step(scene.dt);
      CHECK(scene.world.thread_wakes() - before == kSteps + checks);
      // A force sum alone (what a multi-stage method asks for): the copy, the sum and the
      // forces copied back in one job too.
      clothlab::Matrix3X f;
      const long before_sum = scene.world.thread_wakes();
      scene.world.compute_forces(scene.world.particles.x, scene.world.particles.v, f);
      CHECK(scene.world.thread_wakes() - before_sum == 1);
      clothlab::Matrix3X f_readable(3, scene.world.particles.size());
      scene.world.compute_forces_readable(scene.world.particles.x, scene.world.particles.v,
                                          f_readable);
      CHECK(identical(f, f_readable));
    }
  }
}

TEST_CASE("fast path: a state spoiled between steps stops the one-job pass before anything moves") {
  // Every thread copies and checks its particles, meets the others at the barrier, and stops
  // there if any found a bad value: the guard then names the step about to be taken and the
  // particle, and no particle has moved. The spoiled particle in the first range, the last, and
  // (on 3 threads) the middle one.
  for (int threads : {1, 2, 3}) {
    for (const Index bad : {Index{5}, Index{900}, Index{1840}}) {
      CAPTURE(threads);
      CAPTURE(bad);
      clothlab::Scene scene = run(cloth(""), true, threads, 10, no_buoyancy);
      clothlab::World& world = scene.world;
      world.particles.x(1, bad) = std::numeric_limits<double>::infinity();
      const Matrix3X x = world.particles.x, v = world.particles.v;
      std::string what;
      try {
        world.step(scene.dt);
      } catch (const clothlab::SimulationError& e) {
        what = e.what();
        CHECK(e.step() == 11);
        CHECK(e.particle() == bad);
      }
      CHECK(what.find("blew up before step 11") != std::string::npos);
      CHECK(identical(world.particles.x, x));
      CHECK(identical(world.particles.v, v));
      CHECK(world.steps == 10);
      // Mended, the world steps on, the threads still there.
      world.particles.x(1, bad) = 0.0;
      world.step(scene.dt);
      CHECK(world.steps == 11);
    }
  }
}

namespace {

// Checks that `colour` colours the graph of constraints (i[k], j[k]) properly and greedily: no
// two constraints sharing a particle share a colour, and each constraint has the smallest colour
// that no earlier constraint at its ends has.
void check_greedy_colouring(Index particles, const std::vector<Index>& i,
                            const std::vector<Index>& j, const std::vector<int>& colour) {
  REQUIRE(colour.size() == i.size());
  std::vector<std::set<int>> at(static_cast<size_t>(particles));
  for (size_t k = 0; k < i.size(); ++k) {
    CAPTURE(k);
    std::set<int> taken = at[static_cast<size_t>(i[k])];
    taken.insert(at[static_cast<size_t>(j[k])].begin(), at[static_cast<size_t>(j[k])].end());
    int smallest = 0;
    while (taken.count(smallest))
      ++smallest;
    REQUIRE(colour[k] == smallest);
    at[static_cast<size_t>(i[k])].insert(colour[k]);
    at[static_cast<size_t>(j[k])].insert(colour[k]);
  }
}

}  // namespace

TEST_CASE("fast path: XPBD's colouring is greedy and proper, and a grid needs few colours") {
  // A random graph, and a star of 150 constraints at one particle: more than one 64-bit word of
  // colours at a particle.
  std::mt19937 random(42);
  std::uniform_int_distribution<Index> particle(0, 59);
  std::vector<Index> i, j;
  for (int k = 0; k < 600; ++k) {
    i.push_back(particle(random));
    j.push_back(particle(random));
  }
  for (Index k = 0; k < 150; ++k) {
    i.push_back(7);
    j.push_back(100 + k);
  }
  std::vector<int> colour;
  const int colours = clothlab::xpbd_colouring(250, i, j, colour);
  check_greedy_colouring(250, i, j, colour);
  CHECK(colours == *std::max_element(colour.begin(), colour.end()) + 1);
  CHECK(colours >= 150);

  // A cloth's constraints, in projection order: colour by colour, every spring with ks > 0 once,
  // no two of a colour at one particle, each colour in the order of the springs.
  clothlab::Scene scene = clothlab::parse_scene(cloth("", "xpbd"), "colours.toml");
  scene.world.step(scene.dt);
  const auto& xpbd = dynamic_cast<const clothlab::Xpbd&>(*scene.world.integrator);
  const clothlab::XpbdConstraints& cs = xpbd.constraints();
  size_t springs = 0;
  for (const char* name : {"springs", "bending"})
    springs += spring_effect(scene.world, name)->springs().size();
  CHECK(cs.size() == springs);
  std::set<std::pair<const clothlab::SpringSet*, size_t>> seen;
  for (int q = 0; q < cs.colours(); ++q) {
    CAPTURE(q);
    std::set<Index> ends;
    for (size_t c = cs.colour_start[static_cast<size_t>(q)];
         c < cs.colour_start[static_cast<size_t>(q) + 1]; ++c) {
      CHECK(ends.insert(cs.i[c]).second);
      CHECK(ends.insert(cs.j[c]).second);
      CHECK(seen.insert({cs.set[c], cs.k[c]}).second);
      CHECK(cs.i[c] == cs.set[c]->i(cs.k[c]));
      CHECK(cs.l0[c] == cs.set[c]->l0(cs.k[c]));
    }
  }
  CHECK(seen.size() == springs);
  // Structural, shear and bending springs of a grid: a dozen colours or so, not hundreds.
  MESSAGE(cs.colours() << " colours for " << cs.size() << " constraints");
  CHECK(cs.colours() <= 16);
}

TEST_CASE("fast path: XPBD's projections in the engine room give the readable bits, 1-4 threads") {
  const std::string text = cloth("[integrator]\n", "xpbd", 30, 28);
  // Dampers, pins, wind, buoyancy and the ground every substep; 4 substeps of 2 iterations.
  std::string scene_text = text;
  scene_text.replace(scene_text.find("dt = 0.0005"), 11,
                     "dt = 0.004\nsubsteps = 4\niterations = 2");
  scene_text.erase(scene_text.rfind("[integrator]\n"));
  const int steps = 60;
  const clothlab::Scene readable = run(scene_text, false, 1, steps);
  const auto& readable_xpbd = dynamic_cast<const clothlab::Xpbd&>(*readable.world.integrator);
  CHECK(readable_xpbd.backend_substeps == 0);
  CHECK((readable.world.particles.x - clothlab::parse_scene(scene_text, "t").world.particles.x)
            .cwiseAbs()
            .maxCoeff() > 1e-3);  // the cloth moved
  for (int threads = 1; threads <= 4; ++threads) {
    for (Index split : {Index{1}, clothlab::Index{2048}}) {
      CAPTURE(threads);
      CAPTURE(split);
      const clothlab::Scene fast = run(scene_text, true, threads, steps, [&](clothlab::World& w) {
        engine_of(w).xpbd_split = split;
      });
      // The engine room took every substep's projections: no silent fallback.
      const auto& xpbd = dynamic_cast<const clothlab::Xpbd&>(*fast.world.integrator);
      CHECK(xpbd.backend_substeps == steps * xpbd.substeps);
      CHECK(identical(fast.world.particles.x, readable.world.particles.x));
      CHECK(identical(fast.world.particles.v, readable.world.particles.v));
    }
  }
}

// A cloth that yields and tears in a storm, stepped by `method` (with `keys` in [integrator]) at
// 2 ms for 400 steps on the readable path and on 2 threads in the engine room, after `edit`:
// springs tear, and both paths give the same positions and rest lengths. The engine room's run.
clothlab::Scene storm_matches_readable(const std::string& method, const std::string& keys,
                                       const std::function<void(clothlab::World&)>& edit) {
  std::string text =
      cloth("[plasticity]\nyield_strain = 0.02\nmax_strain = 0.4\n[tearing]\nstrain = 0.08\n",
            method, 24, 24);
  text.replace(text.find("wind = [3, 0, 2]"), 16, "wind = [0, 0, 60]");
  text.replace(text.find("dt = 0.0005"), 11, "dt = 0.002\n" + keys);
  clothlab::Scene readable = run(text, false, 1, 400);
  clothlab::Scene threaded = run(text, true, 2, 400, edit);
  clothlab::Scene built = clothlab::parse_scene(text, "t");
  REQUIRE(spring_effect(threaded.world, "springs")->springs().size() <
          spring_effect(built.world, "springs")->springs().size());  // springs tore
  CHECK(identical(threaded.world.particles.x, readable.world.particles.x));
  CHECK(spring_effect(threaded.world, "springs")->springs().l0() ==
        spring_effect(readable.world, "springs")->springs().l0());
  return threaded;
}

TEST_CASE("fast path: XPBD with tearing and plasticity recolours and matches the readable path") {
  const clothlab::Scene threaded = storm_matches_readable(
      "xpbd", "substeps = 2", [](clothlab::World& w) { engine_of(w).xpbd_split = 1; });
  const auto& xpbd = dynamic_cast<const clothlab::Xpbd&>(*threaded.world.integrator);
  CHECK(xpbd.backend_substeps == 400 * 2);
}

TEST_CASE("fast path: VBD's sweeps in the engine room give the readable bits, 1-4 threads") {
  // Springs, bending and dampers as the vertex steps' energy; pins, wind, drag, buoyancy and
  // gravity as external forces; the ground after every step; 3 sweeps at 4 ms, from the adaptive
  // guess (which reads the last step's velocities).
  std::string text = cloth("", "vbd", 30, 28);
  text.replace(text.find("dt = 0.0005"), 11,
               "dt = 0.004\niterations = 3\ninitial_guess = \"adaptive\"");
  const int steps = 60;
  const clothlab::Scene readable = run(text, false, 1, steps);
  const auto& readable_vbd = dynamic_cast<const clothlab::Vbd&>(*readable.world.integrator);
  CHECK(readable_vbd.backend_steps == 0);
  CHECK((readable.world.particles.x - clothlab::parse_scene(text, "t").world.particles.x)
            .cwiseAbs()
            .maxCoeff() > 1e-3);  // the cloth moved
  for (int threads = 1; threads <= 4; ++threads) {
    for (Index split : {Index{1}, clothlab::Index{1024}}) {
      CAPTURE(threads);
      CAPTURE(split);
      const clothlab::Scene fast = run(text, true, threads, steps,
                                       [&](clothlab::World& w) { engine_of(w).vbd_split = split; });
      // The engine room took every step's sweeps: no silent fallback.
      const auto& vbd = dynamic_cast<const clothlab::Vbd&>(*fast.world.integrator);
      CHECK(vbd.backend_steps == steps);
      CHECK(identical(fast.world.particles.x, readable.world.particles.x));
      CHECK(identical(fast.world.particles.v, readable.world.particles.v));
    }
  }
}

TEST_CASE(
    "fast path: VBD with tearing and plasticity rebuilds its graph and matches the readable "
    "path") {
  const clothlab::Scene threaded = storm_matches_readable(
      "vbd", "iterations = 4", [](clothlab::World& w) { engine_of(w).vbd_split = 1; });
  const auto& vbd = dynamic_cast<const clothlab::Vbd&>(*threaded.world.integrator);
  CHECK(vbd.backend_steps == 400);
  CHECK(vbd.graph_builds > 1);
}

// The local/global solver's engine room: the local steps and right-hand sides are the readable
// loop's operations, so the first local step gives the same d bit for bit; the solve is CHOLMOD's
// factor of the same matrix A where the readable loop has Eigen's, so the positions agree
// within rounding. The bound: each is a backward-stable Cholesky solve, whose relative error is
// at most kappa(A) gamma_{3n+1} (Higham, "Accuracy and Stability of Numerical Algorithms",
// theorem 10.4, n unknowns, gamma_m = m eps / (1 - m eps)), and kappa(A) is at most the largest
// Gershgorin row bound over the smallest eigenvalue, itself at least the smallest mass (A = M +
// a positive semi-definite part). Two such solves differ by at most twice that. An iteration
// does not amplify a difference in x (the local step is a projection and the global step's
// A^-1 h^2 L has norm below 1 for springs near their rest length), and a step carries it over
// through v = (x - x_n) / h and back by h v, so after `steps` steps of `iterations` the
// positions differ by at most steps * iterations * 2 kappa gamma_{3n+1} * max |x|.
TEST_CASE(
    "fast path: local/global in the engine room: the readable d bit for bit, x within the "
    "solves' rounding, 1-4 threads") {
  std::string text = cloth("", "local-global", 30, 28);
  text.replace(text.find("dt = 0.0005"), 11, "dt = 0.004\niterations = 10");
  const int steps = 60;
  const clothlab::Scene readable = run(text, false, 1, steps);
  const auto& readable_lg = dynamic_cast<const clothlab::LocalGlobal&>(*readable.world.integrator);
  CHECK(readable_lg.backend_steps == 0);
  const Matrix3X& x_read = readable.world.particles.x;
  CHECK((x_read - clothlab::parse_scene(text, "t").world.particles.x).cwiseAbs().maxCoeff() >
        1e-2);  // the cloth moved

  // The bound above, from the system's matrix.
  const clothlab::LocalGlobalSystem& system = readable_lg.system();
  const Eigen::SparseMatrix<double>& a = system.a;
  double gershgorin = 0.0;
  Eigen::VectorXd row_sum = Eigen::VectorXd::Zero(a.rows());
  for (Index c = 0; c < a.outerSize(); ++c) {
    for (Eigen::SparseMatrix<double>::InnerIterator e(a, c); e; ++e)
      row_sum[e.row()] += std::abs(e.value());
  }
  gershgorin = row_sum.maxCoeff();
  const double kappa = gershgorin / readable.world.particles.m.minCoeff();
  const double eps = std::numeric_limits<double>::epsilon();
  const double m3 = (3.0 * static_cast<double>(a.rows()) + 1.0) * eps;
  const double gamma = m3 / (1.0 - m3);
  const int iterations = readable_lg.iterations;
  const double bound = steps * iterations * 2.0 * kappa * gamma * x_read.cwiseAbs().maxCoeff();
  MESSAGE("kappa(A) <= " << kappa << ", bound " << bound << " m");
  REQUIRE(bound < 1e-6);  // a bound that can tell a wrong step from rounding

  Matrix3X x_one_thread;
  for (int threads = 1; threads <= 4; ++threads) {
    CAPTURE(threads);
    const clothlab::Scene fast = run(text, true, threads, steps);
    const auto& lg = dynamic_cast<const clothlab::LocalGlobal&>(*fast.world.integrator);
    CHECK(lg.backend_steps == steps);  // the engine room took every step: no silent fallback
    const double difference = (fast.world.particles.x - x_read).cwiseAbs().maxCoeff();
    MESSAGE(threads << " threads: positions differ by " << difference << " m at most");
    CHECK(difference <= bound);
    // The threads split the local steps and the rows, never a sum: the same bits on any number.
    if (threads == 1) x_one_thread = fast.world.particles.x;
    CHECK(identical(fast.world.particles.x, x_one_thread));
  }

  // One step of one iteration: the local step read the same x, so d is the same, bit for bit.
  std::string one = text;
  one.replace(one.find("iterations = 10"), 15, "iterations = 1");
  const clothlab::Scene r1 = run(one, false, 1, 1);
  for (int threads = 1; threads <= 4; ++threads) {
    CAPTURE(threads);
    const clothlab::Scene f1 = run(one, true, threads, 1);
    const auto& lg_r = dynamic_cast<const clothlab::LocalGlobal&>(*r1.world.integrator);
    const auto& lg_f = dynamic_cast<const clothlab::LocalGlobal&>(*f1.world.integrator);
    CHECK(lg_f.backend_steps == 1);
    CHECK(identical(lg_f.system().d, lg_r.system().d));
  }
}
