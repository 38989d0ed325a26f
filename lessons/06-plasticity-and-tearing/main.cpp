// Lesson 06: springs that yield and springs that break. Measures what the lesson's README quotes:
//   1. one spring held past its yield strain, then let go: its rest length against the formula;
//   2. plastic flow never raises a spring's energy, over a sweep of lengths and steps;
//   3. stretched-sheet.toml with and without [plasticity]: the length it keeps once unloaded;
//   4. tearing-sheet.toml: springs, triangles and torn count over time;
//   5. the same tear with the spring list reversed, and a tie broken by end particles.
// `lesson06 SCENE.toml` prints only the tearing table (part 4) for any scene, e.g. storm-flag.toml.
// ./build/lesson06 runs on the reference solutions, ./build/lesson06-student on your exercises;
// while an exercise is still a stub, the program names it and exits with code 4.
#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/after_step/plasticity.hpp"
#include "clothlab/after_step/tearing.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "scene/scene.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

using Ends = std::set<std::pair<Index, Index>>;

const Tearing* tearing_of(const World& world) {
  for (const auto& effect : world.post_step_effects)
    if (const auto* tearing = dynamic_cast<const Tearing*>(effect.get())) return tearing;
  return nullptr;
}

template <class Effects>
void remove_effect(Effects& effects, std::string_view name) {
  std::erase_if(effects, [&](const auto& effect) { return effect->name() == name; });
}

Ends end_pairs(const SpringSet& s) {
  Ends ends;
  for (size_t k = 0; k < s.size(); ++k)
    ends.insert({std::min(s.i(k), s.j(k)), std::max(s.i(k), s.j(k))});
  return ends;
}

void one_spring() {
  const PlasticLimits limits{0.1, 10.0, 0.5};  // yield 10 %, flow 10 /s, at most 50 %
  const double dt = 1e-3;                      // [s]
  fmt::print(
      "1. One spring built 1 m long, held at length l, yield 0.1, flow_rate 10/s, dt 1 ms\n");
  fmt::print("   {:>6}  {:>8}  {:>10}  {:>10}  {:>10}  {:>15}\n", "l [m]", "target", "l0 0.1 s",
             "formula", "l0 1 s", "let go: l0 1 s");
  for (const double l : {1.05, 1.3, 2.0, 0.7}) {
    const double target = l > 1.0 ? l / 1.1 : l / 0.9;
    double l0 = 1.0, at_01 = 0.0;
    for (int n = 1; n <= 1000; ++n) {
      l0 = plastic_rest_length(l, l0, 1.0, limits, dt);
      if (n == 100) at_01 = l0;
    }
    // l0(t) = target + (1 - target) (1 - flow_rate dt)^n, until the clamp to [0.5, 1.5] m.
    const double formula = std::abs(l - 1.0) <= 0.1
                               ? 1.0
                               : std::min(1.5, target + (1.0 - target) * std::pow(0.99, 100));
    double released = l0;  // let go: the spring sits at its own rest length, strain 0
    for (int n = 0; n < 1000; ++n)
      released = plastic_rest_length(released, released, 1.0, limits, dt);
    fmt::print("   {:>6}  {:>8.4f}  {:>10.6f}  {:>10.6f}  {:>10.6f}  {:>15.6f}\n", l, target, at_01,
               formula, l0, released);
  }
  fmt::print(
      "   Within the yield strain nothing moves; past it l0 flows to l / (1 +- 0.1), and at\n"
      "   2 m the clamp stops it at 1.5 m. Let go, the spring keeps the rest length it has.\n\n");
}

void energy_sweep() {
  int cases = 0, yielded = 0, gained = 0;
  double worst = 0.0;  // largest (energy after) / (energy before)
  for (const double dt : {1e-4, 1e-3, 0.05, 1.0}) {
    for (int a = 0; a <= 60; ++a) {
      for (int b = 0; b <= 30; ++b) {
        const double l = 0.4 + 0.03 * a, l0 = 0.6 + 0.03 * b;  // [m], l_built = 1 m
        const double l0_new = plastic_rest_length(l, l0, 1.0, PlasticLimits{0.1, 10.0, 0.5}, dt);
        const double before = (l - l0) * (l - l0), after = (l - l0_new) * (l - l0_new);
        ++cases;
        if (l0_new != l0) ++yielded;
        if (after > before) ++gained;
        if (before > 0.0) worst = std::max(worst, after / before);
      }
    }
  }
  fmt::print(
      "2. Plastic flow and energy: {} cases (l 0.4-2.2 m, l0 0.6-1.5 m, dt 0.1 ms-1 s),\n"
      "   {} of them yield; largest 1/2 ks (l - l0')^2 over 1/2 ks (l - l0)^2: {:.6f};\n"
      "   cases where the energy went up: {}\n\n",
      cases, yielded, worst, gained);
}

// Steps the scene to its duration; returns the middle column's length and its rest length.
std::pair<double, double> column(Scene& scene) {
  World& w = scene.world;
  const Index cols = scene.cloth->cols, rows = scene.cloth->rows,
              mid = scene.cloth->at(0, cols / 2);
  double rest = 0.0;
  const SpringSet& s = springs_of(w);
  for (size_t k = 0; k < s.size(); ++k) {
    const Index lo = std::min(s.i(k), s.j(k)), hi = std::max(s.i(k), s.j(k));
    if ((lo - mid) % cols == 0 && hi == lo + cols) rest += s.l0(k);
  }
  return {w.particles.x(1, mid) - w.particles.x(1, mid + (rows - 1) * cols), rest};
}

void stretched_sheet() {
  fmt::print("3. stretched-sheet.toml: the middle column, built 1 m long [m]\n");
  fmt::print("   {:>16}  {:>12}  {:>12}  {:>14}\n", "", "loaded", "rest length", "gravity off");
  for (const bool plastic : {false, true}) {
    Scene scene = load_scene_file(lesson_file("stretched-sheet.toml"));
    if (!plastic) remove_effect(scene.world.post_step_effects, "plasticity");
    for (long n = 0; n < scene.step_count(); ++n)
      scene.world.step(scene.dt);
    const auto [loaded, rest] = column(scene);
    remove_effect(scene.world.force_effects, "gravity");  // the load goes away
    for (long n = 0; n < scene.step_count(); ++n)
      scene.world.step(scene.dt);
    fmt::print("   {:>16}  {:>12.4f}  {:>12.4f}  {:>14.4f}\n",
               plastic ? "with plasticity" : "elastic only", loaded, rest, column(scene).first);
  }
  fmt::print("\n");
}

// Steps a scene with [tearing], printing the counts whenever springs tore in the last 0.1 s.
Ends tear_table(Scene& scene, const char* name) {
  World& w = scene.world;
  const Tearing* tearing = tearing_of(w);
  if (!tearing) throw std::runtime_error(fmt::format("{} has no [tearing] table", name));
  fmt::print("4. {}: {} springs, {} triangles at the start\n", name, springs_of(w).size(),
             w.triangles.size());
  fmt::print("   {:>7}  {:>7}  {:>8}  {:>10}\n", "t [s]", "torn", "springs", "triangles");
  const long every = std::max(1L, std::lround(0.1 / scene.dt));
  long shown = 0;
  for (long n = 1; n <= scene.step_count(); ++n) {
    const long before = tearing->torn();
    w.step(scene.dt);
    if (before == 0 && tearing->torn() > 0) fmt::print("   first tear at t = {:.3f} s\n", w.t);
    if ((n % every == 0 || n == scene.step_count()) && tearing->torn() != shown) {
      shown = tearing->torn();
      fmt::print("   {:>7.2f}  {:>7}  {:>8}  {:>10}\n", w.t, shown, springs_of(w).size(),
                 w.triangles.size());
    }
  }
  return end_pairs(springs_of(w));
}

void order_independence() {
  Scene as_built = load_scene_file(lesson_file("tearing-sheet.toml"));
  Scene reversed = load_scene_file(lesson_file("tearing-sheet.toml"));
  SpringSet& s = springs_of(reversed.world);
  s.reverse();  // the list in the opposite order, and every spring turned end for end
  for (long n = 0; n < as_built.step_count(); ++n) {
    as_built.world.step(as_built.dt);
    reversed.world.step(reversed.dt);
  }
  const bool same = end_pairs(springs_of(as_built.world)) == end_pairs(springs_of(reversed.world));
  fmt::print(
      "5. tearing-sheet.toml with its spring list reversed: {} and {} torn, same springs "
      "left: {}\n",
      tearing_of(as_built.world)->torn(), tearing_of(reversed.world)->torn(), same ? "yes" : "no");
  // A tie: four springs at the same strain, at most two tear, listed in two orders.
  const std::vector<double> strain(4, 0.6);
  const std::vector<std::pair<Index, Index>> ends{{7, 8}, {0, 1}, {3, 4}, {1, 2}};
  const std::vector<std::pair<Index, Index>> back(ends.rbegin(), ends.rend());
  auto chosen = [&](const std::vector<std::pair<Index, Index>>& e) {
    std::string out;
    for (const size_t k : select_tears(strain, e, 0.5, 2))
      out += fmt::format(" ({}, {})", e[k].first, e[k].second);
    return out;
  };
  fmt::print("   a tie of four at strain 0.6, max 2: listed one way{}, the other way{}\n",
             chosen(ends), chosen(back));
}

}  // namespace

int main(int argc, char** argv) {
  return lesson::run("lesson06", [&] {
    if (argc > 1) {
      for (int a = 1; a < argc; ++a) {
        Scene scene = load_scene_file(argv[a]);
        tear_table(scene, argv[a]);
      }
      return;
    }
    one_spring();
    energy_sweep();
    stretched_sheet();
    Scene sheet = load_scene_file(lesson_file("tearing-sheet.toml"));
    tear_table(sheet, "tearing-sheet.toml");
    fmt::print("\n");
    order_independence();
  });
}
