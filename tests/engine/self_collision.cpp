// The spatial hash and self-collision (lesson 10): what must hold for any scene.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "clothlab/after_step/self_collision.hpp"
#include "clothlab/after_step/spatial_hash.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;
using clothlab::IndexPair;
using clothlab::Matrix3X;
using clothlab::Vec3;

namespace {

const std::string kLesson = std::string(CLOTHLAB_SOURCE_DIR) + "/lessons/10-collision-detection/";

// n points spread uniformly over the box [lo, hi]^3 [m], the same on every machine: the raw 64-bit
// output of mt19937_64 is specified by the standard (its distributions are not).
Matrix3X random_cloud(Index n, double lo, double hi, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  Matrix3X x(3, n);
  for (Index i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      const double u = static_cast<double>(random() >> 11) / 9007199254740992.0;  // [0, 1)
      x(k, i) = lo + (hi - lo) * u;
    }
  }
  return x;
}

std::vector<IndexPair> hashed_pairs(const Matrix3X& x, double h) {
  clothlab::SpatialHash hash;
  hash.build(x, h, 1e6);
  std::vector<IndexPair> pairs;
  hash.find_pairs(x, h, pairs);
  return pairs;
}

std::vector<IndexPair> brute_pairs(const Matrix3X& x, double h) {
  std::vector<IndexPair> pairs;
  clothlab::brute_force_pairs(x, h, pairs);
  return pairs;
}

clothlab::SelfCollision* self_collision_of(clothlab::World& world) {
  return test::find_post_step_effect<clothlab::SelfCollision>(world);
}

// The smallest distance [m] between two particles that were at least `thickness` apart at rest
// (x_rest), by testing every pair.
double closest_non_neighbours(const Matrix3X& x, const Matrix3X& x_rest, double thickness) {
  double closest = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < x.cols(); ++i) {
    for (Index j = i + 1; j < x.cols(); ++j) {
      if ((x_rest.col(j) - x_rest.col(i)).norm() < thickness) continue;
      closest = std::min(closest, (x.col(j) - x.col(i)).norm());
    }
  }
  return closest;
}

// The towel of lesson 10: how close its layers come, and whether its halves swap sides.
struct TowelRun {
  double closest = std::numeric_limits<double>::infinity();  // [m] over the checked steps
  double most_crossed =
      -std::numeric_limits<double>::infinity();  // [m] max of z(row 0) - z(row 20)
  bool pins_still = true;
};

TowelRun run_towel(const std::string& file, int steps) {
  clothlab::Scene scene = clothlab::load_scene_file(kLesson + file);
  clothlab::World& w = scene.world;
  const clothlab::ClothGrid g = *scene.cloth;
  const Matrix3X x_rest = w.particles.x;
  TowelRun run;
  for (int n = 1; n <= steps; ++n) {
    w.step(scene.dt);
    if (n % 20 != 0) continue;
    run.closest = std::min(run.closest, closest_non_neighbours(w.particles.x, x_rest, 0.06));
    // Row 0 starts at z = -0.5, row 20 at z = +0.5; by symmetry their mean z stay opposite.
    double z0 = 0.0, z20 = 0.0;
    for (Index c = 0; c < g.cols; ++c) {
      z0 += w.particles.x(2, g.at(0, c)) / static_cast<double>(g.cols);
      z20 += w.particles.x(2, g.at(20, c)) / static_cast<double>(g.cols);
    }
    run.most_crossed = std::max(run.most_crossed, z0 - z20);
    for (Index c = 0; c < g.cols; ++c) {
      run.pins_still = run.pins_still && w.particles.x.col(g.at(10, c)) == x_rest.col(g.at(10, c));
    }
  }
  return run;
}

}  // namespace

TEST_CASE("spatial hash: finds exactly the pairs a brute-force search finds") {
  // Random clouds on both sides of zero, several seeds and cell sizes; from sparse (few pairs)
  // to crowded (tens of particles a cell, many slots shared).
  for (std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    for (double h : {0.05, 0.13, 0.4}) {
      for (Index n : {Index{50}, Index{400}}) {
        const Matrix3X x = random_cloud(n, -1.0, 0.7, seed);
        const std::vector<IndexPair> expected = brute_pairs(x, h);
        CAPTURE(seed);
        CAPTURE(h);
        CAPTURE(n);
        CAPTURE(expected.size());
        CHECK(hashed_pairs(x, h) == expected);
      }
    }
  }
}

TEST_CASE("spatial hash: points on cell faces and corners, and far from the origin") {
  // A lattice of spacing h / 2 from -2 h to 2 h: every point lies on cell faces (and corners),
  // and its neighbours are h / 2, 0.71 h and 0.87 h away (inside h) or h and more (outside).
  const double h = 0.25;  // a power of two: the lattice points are exact
  Matrix3X lattice(3, 9 * 9 * 9);
  Index k = 0;
  for (int i = -4; i <= 4; ++i) {
    for (int j = -4; j <= 4; ++j) {
      for (int l = -4; l <= 4; ++l)
        lattice.col(k++) = Vec3(i, j, l) * (h / 2.0);
    }
  }
  const std::vector<IndexPair> expected = brute_pairs(lattice, h);
  // An inner point has 6 + 12 + 8 = 26 neighbours closer than h (7448 pairs in all); pairs at
  // exactly h are not "closer than h" for either method.
  CHECK(expected.size() > 5000);
  CHECK(hashed_pairs(lattice, h) == expected);
  // The same cloud shifted far out, 1e4 cells from the origin: large cell coordinates.
  const Matrix3X far = (lattice.colwise() + Vec3(-2500.0, 1250.0, -3000.0)).eval();
  CHECK(hashed_pairs(far, h) == brute_pairs(far, h));
  // All points in one cell: every pair is a candidate.
  const Matrix3X crowd = random_cloud(300, 0.0, 0.2, 7);
  CHECK(hashed_pairs(crowd, h) == brute_pairs(crowd, h));
}

TEST_CASE("spatial hash: particles beyond the bound are left out, not hashed") {
  Matrix3X x(3, 4);
  x.col(0) = Vec3(0.0, 0.0, 0.0);
  x.col(1) = Vec3(0.01, 0.0, 0.0);
  x.col(2) = Vec3(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
  x.col(3) = Vec3(1e300, 0.0, 0.0);
  clothlab::SpatialHash hash;
  hash.build(x, 0.05, 1e6);
  std::vector<IndexPair> pairs;
  hash.find_pairs(x, 0.05, pairs);
  CHECK(pairs == std::vector<IndexPair>{{0, 1}});
  CHECK(hash.builds() == 1);
}

TEST_CASE("self-collision: the towel's halves stop against each other instead of passing through") {
  // 1.5 s: the halves meet below the line between t = 0.25 s and 0.5 s and would, without
  // self-collision, have swung through each other and up the other side by then.
  const TowelRun with = run_towel("towel-on-a-line.toml", 3000);
  const TowelRun without = run_towel("towel-passing-through.toml", 3000);
  CAPTURE(with.closest);
  CAPTURE(without.closest);
  CAPTURE(with.most_crossed);
  CAPTURE(without.most_crossed);
  // Without [self_collision] the half that started at z < 0 ends up beyond the other: row 0
  // swings past row 20 (the test can fail), and particles of the two layers meet.
  CHECK(without.most_crossed > 0.1);
  CHECK(without.closest < 0.2 * 0.06);
  // With it, row 0 stays on its side, and no two particles that were not neighbours at rest come
  // closer than the thickness, 0.06 m, by more than 1 % (measured: 0.0600 m to five digits; the
  // passes stop only when a detection finds nothing, or after `iterations` passes).
  CHECK(with.most_crossed < 0.0);
  CHECK(with.closest > 0.99 * 0.06);
  // The line holds: the pinned middle row never moved, bit for bit.
  CHECK(with.pins_still);
}

TEST_CASE("self-collision: a scene without [self_collision] builds no hash") {
  clothlab::Scene without = clothlab::load_scene_file(kLesson + "towel-passing-through.toml");
  CHECK(self_collision_of(without.world) == nullptr);
  for (const auto& e : without.world.post_step_effects)
    CHECK(e->name() != "self_collision");
  CHECK(without.world.effects_in_play().find("self_collision") == std::string::npos);

  // With the table: one effect, one build of the hash a detection pass, at least one a step.
  clothlab::Scene with = clothlab::load_scene_file(kLesson + "towel-on-a-line.toml");
  clothlab::SelfCollision* s = self_collision_of(with.world);
  REQUIRE(s != nullptr);
  CHECK(s->hash_builds() == 0);
  for (int n = 0; n < 10; ++n)
    with.world.step(with.dt);
  CHECK(s->hash_builds() >= 10);
  CHECK(s->hash_builds() <= 40);  // iterations = 4
}

TEST_CASE("self-collision: pinned particles never move under the response") {
  // Particle 0 pinned, particle 1 free and falling on it at 1 m/s; particles 2 and 3 both
  // pinned. The scene builds them 0.1 m apart (more than the thickness, 0.05 m, so no pair is
  // excluded at rest); then particles 1 and 3 are moved in to 2 cm and 1 cm.
  clothlab::Scene fresh = clothlab::parse_scene(R"(
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
pinned = true
[[particle]]
position = [0.0, 0.1, 0.0]
velocity = [0.0, -1.0, 0.0]
mass = 0.5
[[particle]]
position = [1.0, 0.0, 0.0]
mass = 1.0
pinned = true
[[particle]]
position = [1.0, 0.1, 0.0]
mass = 1.0
pinned = true
[self_collision]
thickness = 0.05
[integrator]
dt = 0.001
duration = 1
)",
                                                "pinned.toml");
  clothlab::World& f = fresh.world;
  f.particles.x.col(1) = Vec3(0.0, 0.02, 0.0);
  f.particles.x.col(3) = Vec3(1.0, 0.01, 0.0);
  const Matrix3X before = f.particles.x;
  clothlab::SelfCollision* s = self_collision_of(f);
  REQUIRE(s != nullptr);
  s->apply(f, clothlab::StepTime::whole(f.t, fresh.dt));
  CHECK(s->last_pairs() == 2);
  // The pinned particles, bit for bit, position and velocity.
  CHECK(f.particles.x.col(0) == before.col(0));
  CHECK(f.particles.x.col(2) == before.col(2));
  CHECK(f.particles.x.col(3) == before.col(3));
  CHECK(f.particles.v.col(0) == Vec3::Zero());
  // The free particle took the whole push, to the thickness, and stopped approaching.
  CHECK(f.particles.x(1, 1) == doctest::Approx(0.05).epsilon(1e-12));
  CHECK(f.particles.v(1, 1) >= 0.0);
}

TEST_CASE("self-collision: pairs closer than the thickness at rest are excluded") {
  // A 5 x 5 cloth 0.05 apart with a thickness of 0.06: the 40 structural neighbours are excluded,
  // the diagonals (0.071) are not. At rest, no pair is found.
  clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 5
cols = 5
spacing = 0.05
mass = 0.1
[springs]
ks = 10
[self_collision]
thickness = 0.06
[integrator]
dt = 0.001
duration = 1
)",
                                                "grid.toml");
  clothlab::World& w = scene.world;
  clothlab::SelfCollision* s = self_collision_of(w);
  REQUIRE(s != nullptr);
  CHECK(s->detect(w.particles.x, 1e6).empty());
  CHECK(s->excluded(0, 1));
  CHECK(s->excluded(0, 5));
  CHECK_FALSE(s->excluded(0, 6));
  // Squeeze the grid to 0.7 of its size: the diagonals, now 0.0495 apart, are found; the
  // structural neighbours (0.035) still are not.
  const Vec3 centre = w.particles.x.rowwise().mean();
  const Matrix3X squeezed = ((w.particles.x.colwise() - centre) * 0.7).colwise() + centre;
  const std::vector<IndexPair>& pairs = s->detect(squeezed, 1e6);
  CHECK(pairs.size() == 2 * 4 * 4);  // two diagonals in each of the 16 cells
  for (const auto& [i, j] : pairs)
    CHECK_FALSE(s->excluded(i, j));
}
