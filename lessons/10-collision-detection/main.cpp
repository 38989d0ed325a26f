// Lesson 10: collision detection and response. Measures what the lesson's README quotes:
//   1. the cells and slots of a few points, and one pair pushed apart (exercises 10.1, 10.2);
//   2. the broad phase against testing every pair: the same pairs, and the time each takes, as
//      the number of particles grows;
//   3. the towel over a line, with and without [self_collision]: how close its layers come,
//      whether its halves pass through each other, the pairs found and the time in the hash;
//   4. the cloth dropped onto a small ball: the same measures on a crumpled cloth.
// `lesson10 SCENE.toml ...` steps each scene and prints its closest pair every 0.5 s.
// ./build/lesson10 runs on the reference solutions, ./build/lesson10-student on your exercises;
// while an exercise is still a stub, the program names it and exits with code 4.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/after_step/self_collision.hpp"
#include "clothlab/after_step/spatial_hash.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "scene/scene.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

SelfCollision* self_collision_of(World& world) {
  for (const auto& effect : world.post_step_effects)
    if (auto* s = dynamic_cast<SelfCollision*>(effect.get())) return s;
  return nullptr;
}

// The closest two particles that were at least `thickness` apart at rest (x_rest) [m], found
// with the spatial hash (cells of `radius` >= any distance of interest), and how many pairs are
// closer than the thickness.
struct Closest {
  double distance = std::numeric_limits<double>::infinity();  // [m]
  long overlapping = 0;
};

Closest closest_pair(const Matrix3X& x, const Matrix3X& x_rest, double thickness, double radius,
                     SpatialHash& hash) {
  hash.build(x, radius, 1e6);
  Closest c;
  hash.for_each_pair(x, radius, [&](Index i, Index j) {
    if ((x_rest.col(j) - x_rest.col(i)).norm() < thickness) return;  // neighbours at rest
    const double d = (x.col(j) - x.col(i)).norm();
    c.distance = std::min(c.distance, d);
    if (d < thickness) ++c.overlapping;
  });
  return c;
}

void by_hand() {
  fmt::print("1. Cells of edge h = 0.25 m, and their slots in a table of 1000 (exercise ex10.1)\n");
  fmt::print("   {:>20}  {:>14}  {:>6}\n", "x [m]", "cell", "slot");
  for (const Vec3& x :
       {Vec3(0.1, 0.3, 0.6), Vec3(-0.1, 0.1, 0.0), Vec3(0.5, -0.5, 0.0), Vec3(0.3, 0.6, 0.9)}) {
    const Cell c = cell_of(x, 0.25);
    fmt::print("   {:>20}  {:>14}  {:>6}\n", fmt::format("({:g}, {:g}, {:g})", x.x(), x.y(), x.z()),
               fmt::format("({}, {}, {})", c.ix, c.iy, c.iz), cell_hash(c, 1000));
  }
  fmt::print(
      "   One pair (exercise ex10.2): r1 = (0, 0, 0), r2 = (0.03, 0, 0.04), thickness 0.06 m\n");
  const SelfContact contact{0.06, 0.0, 0.3, 0.2};
  for (const auto& [w1, w2] : {std::pair{1.0, 1.0}, {3.0, 1.0}, {0.0, 1.0}}) {
    const PairState out =
        pair_response({Vec3::Zero(), Vec3::Zero(), Vec3(0.03, 0.0, 0.04), Vec3(-0.6, 0.0, -0.8)},
                      w1, w2, contact);
    fmt::print(
        "   w1 = {:g}, w2 = {:g}: r1' = ({:.4f}, 0, {:.4f}), r2' = ({:.4f}, 0, {:.4f}), d' = "
        "{:.4f}, "
        "v1' = ({:.2f}, 0, {:.2f}), v2' = ({:.2f}, 0, {:.2f})\n",
        w1, w2, out.r1.x(), out.r1.z(), out.r2.x(), out.r2.z(), (out.r2 - out.r1).norm(),
        out.v1.x(), out.v1.z(), out.v2.x(), out.v2.z());
  }
}

// n particles spread at random, 2 in each cube of edge 0.05 m on average: as crowded as a cloth
// 0.05 m apart crumpled into layers 0.05 m apart.
Matrix3X cloud(Index n, std::uint64_t seed) {
  const double side = 0.05 * std::cbrt(static_cast<double>(n) / 2.0);  // [m]
  std::uint64_t state = seed;
  Matrix3X x(3, n);
  for (Index i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      x(k, i) = side * (static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5);
    }
  }
  return x;
}

void broad_phase() {
  fmt::print(
      "\n2. Pairs closer than 0.05 m among n random particles, 2 to a (0.05 m)^3: every pair "
      "against the hash\n");
  fmt::print("   {:>7}  {:>12}  {:>9}  {:>14}  {:>11}  {:>11}  {:>8}\n", "n", "pairs tested",
             "found", "brute force", "hash build", "hash query", "speed-up");
  SpatialHash hash;
  std::vector<IndexPair> brute, hashed;
  for (Index n : {Index{500}, Index{2000}, Index{8000}, Index{32000}}) {
    const Matrix3X x = cloud(n, 42);
    const double h = 0.05;
    // Small cases are repeated, so that each time is long enough to measure.
    const int repeats = n <= 2000 ? 50 : 5;
    const int brute_repeats = n <= 2000 ? repeats : 1;  // 32,000 particles take seconds
    const auto t0 = Clock::now();
    for (int r = 0; r < brute_repeats; ++r)
      brute_force_pairs(x, h, brute);
    const double t_brute = seconds_since(t0) / brute_repeats;
    hash.build(x, h, 1e6);  // once to size the vectors, as the first step of a run does
    const auto t1 = Clock::now();
    for (int r = 0; r < repeats; ++r)
      hash.build(x, h, 1e6);
    const double t_build = seconds_since(t1) / repeats;
    long found = 0;
    const auto t2 = Clock::now();
    for (int r = 0; r < repeats; ++r)
      hash.for_each_pair(x, h, [&](Index, Index) { ++found; });
    const double t_query = seconds_since(t2) / repeats;
    hash.find_pairs(x, h, hashed);  // the same pairs? (sorted, untimed)
    fmt::print("   {:>7}  {:>12.3g}  {:>9}  {:>11.2f} ms  {:>8.2f} ms  {:>8.2f} ms  {:>7.1f}x{}\n",
               n, 0.5 * static_cast<double>(n) * static_cast<double>(n - 1), brute.size(),
               1e3 * t_brute, 1e3 * t_build, 1e3 * t_query, t_brute / (t_build + t_query),
               hashed == brute && found == repeats * static_cast<long>(brute.size())
                   ? ""
                   : "  DIFFERENT PAIRS");
  }
}

struct TowelResult {
  double closest = std::numeric_limits<double>::infinity();   // [m] non-neighbours, all checks
  double crossed = -std::numeric_limits<double>::infinity();  // [m] max of z(row 0) - z(row 20)
  double seconds = 0.0;                                       // [s] wall time of the steps
};

TowelResult towel(const char* file, bool print) {
  Scene scene = load_scene_file(lesson_file(file));
  World& w = scene.world;
  const ClothGrid g = *scene.cloth;
  const Matrix3X x_rest = w.particles.x;
  SpatialHash measure;  // for the measurements, apart from the effect's own
  TowelResult r;
  const long every = std::lround(0.25 / scene.dt);
  if (print) {
    fmt::print("   {:>6}  {:>12}  {:>12}  {:>14}\n", "t [s]", "closest [m]", "overlaps",
               "z0 - z20 [m]");
  }
  for (long n = 1; n <= scene.step_count(); ++n) {
    const auto t0 = Clock::now();
    w.step(scene.dt);
    r.seconds += seconds_since(t0);
    if (n % 10 != 0) continue;
    const Closest c = closest_pair(w.particles.x, x_rest, 0.06, 0.12, measure);
    r.closest = std::min(r.closest, c.distance);
    double z0 = 0.0, z20 = 0.0;
    for (Index col = 0; col < g.cols; ++col) {
      z0 += w.particles.x(2, g.at(0, col)) / static_cast<double>(g.cols);
      z20 += w.particles.x(2, g.at(g.rows - 1, col)) / static_cast<double>(g.cols);
    }
    r.crossed = std::max(r.crossed, z0 - z20);
    if (print && n % every == 0) {
      fmt::print("   {:>6.2f}  {:>12}  {:>12}  {:>14.3f}\n", w.t,
                 std::isfinite(c.distance) ? fmt::format("{:.4f}", c.distance) : "-", c.overlapping,
                 z0 - z20);
    }
  }
  return r;
}

void towels() {
  fmt::print(
      "\n3. The towel over a line, 3 s; closest = closest two particles that were not "
      "neighbours at rest,\n   overlaps = such pairs closer than the thickness 0.06 m, "
      "z0 - z20 = row 0's z minus row 20's (< 0: on their own sides)\n");
  fmt::print("   towel-passing-through.toml (no [self_collision]):\n");
  const TowelResult without = towel("towel-passing-through.toml", true);
  fmt::print("   towel-on-a-line.toml (with [self_collision]):\n");
  const TowelResult with = towel("towel-on-a-line.toml", true);
  fmt::print(
      "   Without: closest {:.4f} m, rows 0 and 20 crossed by up to {:.3f} m: the halves pass "
      "through each other.\n"
      "   With:    closest {:.5f} m ({:.2f} % of the thickness), rows never crossed (largest "
      "z0 - z20 = {:.3f} m).\n"
      "   Wall time of the 6000 steps: {:.2f} s without, {:.2f} s with.\n",
      without.closest, without.crossed, with.closest, 100.0 * with.closest / 0.06, with.crossed,
      without.seconds, with.seconds);
}

void ball() {
  fmt::print("\n4. cloth-on-ball.toml: 625 particles dropped on a ball of radius 0.25 m, 2.5 s\n");
  Scene scene = load_scene_file(lesson_file("cloth-on-ball.toml"));
  World& w = scene.world;
  SelfCollision* s = self_collision_of(w);
  const Matrix3X x_rest = w.particles.x;
  SpatialHash measure;
  double closest = std::numeric_limits<double>::infinity();
  long most_pairs = 0, passes = 0;
  double step_seconds = 0.0;
  fmt::print("   {:>6}  {:>12}  {:>14}  {:>12}\n", "t [s]", "closest [m]", "pairs a step",
             "lowest y [m]");
  const long every = std::lround(0.5 / scene.dt);
  for (long n = 1; n <= scene.step_count(); ++n) {
    const auto t0 = Clock::now();
    w.step(scene.dt);
    step_seconds += seconds_since(t0);
    most_pairs = std::max(most_pairs, static_cast<long>(s->last_pairs()));
    passes += s->last_passes();
    if (n % 10 != 0) continue;
    const Closest c = closest_pair(w.particles.x, x_rest, 0.06, 0.12, measure);
    closest = std::min(closest, c.distance);
    if (n % every == 0) {
      fmt::print("   {:>6.2f}  {:>12.4f}  {:>14}  {:>12.4f}\n", w.t, c.distance, s->last_pairs(),
                 w.particles.x.row(1).minCoeff());
    }
  }
  const double steps = static_cast<double>(scene.step_count());
  fmt::print(
      "   Closest non-neighbours over the run: {:.5f} m ({:.2f} % of the thickness); at most {} "
      "pairs in one step.\n"
      "   {} hash builds, {:.2f} a step; {} pair responses in all.\n"
      "   Time: {:.3f} ms a step, of which {:.3f} ms in detection (hash and pairs, {:.0f} %).\n",
      closest, 100.0 * closest / 0.06, most_pairs, s->hash_builds(),
      static_cast<double>(passes) / steps, s->total_pairs(), 1e3 * step_seconds / steps,
      1e3 * s->detect_seconds() / steps, 100.0 * s->detect_seconds() / step_seconds);
}

void closest_table(const char* path) {
  Scene scene = load_scene_file(path);
  World& w = scene.world;
  SelfCollision* s = self_collision_of(w);
  const double thickness = s ? s->contact().thickness : 0.06;
  fmt::print("{}: closest non-neighbours every 0.5 s (thickness {} m{})\n", path, thickness,
             s ? "" : ", no [self_collision]: 0.06 m for the measure");
  const Matrix3X x_rest = w.particles.x;
  SpatialHash measure;
  const long every = std::max(1L, std::lround(0.5 / scene.dt));
  for (long n = 1; n <= scene.step_count(); ++n) {
    w.step(scene.dt);
    if (n % every == 0 || n == scene.step_count()) {
      const Closest c = closest_pair(w.particles.x, x_rest, thickness, 2.0 * thickness, measure);
      fmt::print("   t = {:>6.2f} s   {:.4f} m, {} pairs closer than the thickness\n", w.t,
                 c.distance, c.overlapping);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  return lesson::run("lesson10", [&] {
    if (argc > 1) {
      for (int a = 1; a < argc; ++a)
        closest_table(argv[a]);
      return;
    }
    by_hand();
    broad_phase();
    towels();
    ball();
  });
}
