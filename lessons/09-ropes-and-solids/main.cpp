// Lesson 09: ropes, soft solids and strain limiting. Measures what the lesson's README quotes:
//   1. one strain-limiting correction, worked by hand (the kernel of exercise ex09.1);
//   2. the jelly cube's springs, family by family, against the counting formulas;
//   3. the soft cloth hanging from two corners, with and without [strain_limit]: its sag, its
//      largest strain, the sweeps strain limiting took, and what stiffer springs would cost;
//   4. the swinging rope with and without [strain_limit]: how far its links stretch;
//   5. the jelly cube dropped on the ground: how it lands and where it comes to rest.
// `lesson09 SCENE.toml ...` steps each scene and prints its largest strain every 0.5 s.
// ./build/lesson09 runs on the reference solutions, ./build/lesson09-student on your exercises;
// while an exercise is still a stub, the program names it and exits with code 4.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "analysis/stability.hpp"
#include "clothlab/after_step/strain_limiting.hpp"
#include "clothlab/bodies/solid.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "scene/scene.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

const StrainLimiting* limiter_of(const World& world) {
  for (const auto& effect : world.post_step_effects)
    if (const auto* s = dynamic_cast<const StrainLimiting*>(effect.get())) return s;
  return nullptr;
}

void remove_limiter(World& world) {
  std::erase_if(world.post_step_effects,
                [](const auto& effect) { return effect->name() == "strain_limit"; });
}

// The largest strain l / l0 - 1 over the scene's springs.
double max_strain(World& world) {
  const SpringSet& s = springs_of(world);
  double worst = -1.0;
  for (size_t k = 0; k < s.size(); ++k) {
    const double l = (world.particles.x.col(s.j(k)) - world.particles.x.col(s.i(k))).norm();
    worst = std::max(worst, l / s.l0(k) - 1.0);
  }
  return worst;
}

void one_spring() {
  fmt::print("1. One correction: r1 = (0, 0, 0), r2 = (6, 0, 8), l0 = 4 m, max_strain = 0.25\n");
  const Vec3 r1 = Vec3::Zero(), r2(6.0, 0.0, 8.0);
  fmt::print("   {:>14}  {:>22}  {:>22}  {:>8}\n", "w1, w2 [1/kg]", "dr1 [m]", "dr2 [m]", "l' [m]");
  for (const auto& [w1, w2] : {std::pair{1.0, 1.0}, {3.0, 1.0}, {0.0, 1.0}, {0.0, 0.0}}) {
    const StrainCorrection c =
        strain_limit_correction(r1, r2, w1, w2, 4.0, StrainLimits{0.25, 1.0});
    const double l = ((r2 + c.dr2) - (r1 + c.dr1)).norm();
    fmt::print(
        "   {:>14}  ({:>5.2f}, {:>4.1f}, {:>5.2f})    ({:>5.2f}, {:>4.1f}, {:>5.2f})    {:>8.4f}\n",
        fmt::format("{:g}, {:g}", w1, w2), c.dr1.x(), c.dr1.y(), c.dr1.z(), c.dr2.x(), c.dr2.y(),
        c.dr2.z(), l);
  }
  fmt::print(
      "   l = 10 is past the limit 1.25 * 4 = 5: C = 5 along e = (0.6, 0, 0.8), split by inverse\n"
      "   mass; a pinned end (w = 0) stays, and two pinned ends leave the spring as it is.\n\n");
}

void solid_counts() {
  Scene scene = load_scene_file(lesson_file("jelly-cube.toml"));
  const SolidLattice& g = *scene.solid;
  const size_t structural = solid_structural_pairs(g.nx, g.ny, g.nz).size();
  const size_t face = solid_face_diagonal_pairs(g.nx, g.ny, g.nz).size();
  const size_t body = solid_body_diagonal_pairs(g.nx, g.ny, g.nz).size();
  const Index cells = (g.nx - 1) * (g.ny - 1) * (g.nz - 1);
  fmt::print("2. jelly-cube.toml: {} x {} x {} particles, {} cells\n", g.nx, g.ny, g.nz, cells);
  fmt::print("   structural {:>5}   3 * (n-1) n^2       = {}\n", structural,
             3 * (g.nx - 1) * g.ny * g.nz);
  fmt::print("   face diag. {:>5}   2 * 3 * (n-1)^2 n   = {}\n", face,
             6 * (g.nx - 1) * (g.ny - 1) * g.nz);
  fmt::print("   body diag. {:>5}   4 * (n-1)^3         = {}\n", body, 4 * cells);
  fmt::print("   in all     {:>5}   the scene's springs = {}; {} surface triangles\n\n",
             structural + face + body, springs_of(scene.world).size(),
             scene.world.triangles.size());
}

struct Hanging {
  double dt = 0.0;      // [s]
  double sag = 0.0;     // the bottom edge's middle below the pins [m]
  double strain = 0.0;  // the largest strain at the end
  double sweeps = 0.0;  // strain-limiting sweeps per step, on average
  double ms_per_step = 0.0;
};

// Hangs the soft cloth for its 5 s: with `sweeps` > 0 strain-limited with that many sweeps at
// most, else without; `stiffer` multiplies every spring constant, at the step `dt` [s].
Hanging hang(int sweeps, double stiffer, double dt) {
  Scene scene = load_scene_file(lesson_file("sagging-cloth.toml"));
  World& w = scene.world;
  SpringSet& springs = springs_of(w);
  for (size_t k = 0; k < springs.size(); ++k)
    springs.set_ks(k, stiffer * springs.ks(k));
  if (sweeps > 0)
    w.post_step_effects.push_back(std::make_unique<StrainLimiting>(
        *find_spring_effect(w, "springs"), StrainLimits{0.1, 1.0}, sweeps));
  const long steps = std::lround(scene.duration / dt);
  const auto start = std::chrono::steady_clock::now();
  for (long n = 0; n < steps; ++n)
    w.step(dt);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const ClothGrid& c = *scene.cloth;
  Hanging h;
  h.dt = dt;
  h.sag = w.particles.x(1, c.at(0, 0)) - w.particles.x(1, c.at(c.rows - 1, c.cols / 2));
  h.strain = max_strain(w);
  if (const StrainLimiting* s = limiter_of(w))
    h.sweeps = static_cast<double>(s->total_sweeps()) / static_cast<double>(steps);
  h.ms_per_step = 1e3 * seconds / static_cast<double>(steps);
  return h;
}

void hanging_cloth() {
  fmt::print("3. The soft cloth (ks = 10 N/m) hanging from its two top corners, after 5 s\n");
  fmt::print("   {:>28}  {:>7}  {:>7}  {:>10}  {:>11}  {:>7}\n", "", "dt [ms]", "sag [m]",
             "max strain", "sweeps/step", "ms/step");
  auto row = [](const std::string& name, const Hanging& h) {
    fmt::print("   {:>28}  {:>7.3f}  {:>7.3f}  {:>10.3f}  {:>11.2f}  {:>7.3f}\n", name, 1e3 * h.dt,
               h.sag, h.strain, h.sweeps, h.ms_per_step);
  };
  const double dt = load_scene_file(lesson_file("sagging-cloth.toml")).dt;
  const Hanging soft = hang(0, 1.0, dt);
  row("soft springs (sagging-cloth)", soft);
  for (const int sweeps : {1, 3, 10, 30}) {
    row(fmt::format("max_strain 0.1, {:>2} sweeps{}", sweeps, sweeps == 10 ? "*" : ""),
        hang(sweeps, 1.0, dt));
  }
  // Without the limit the springs would have to be this much stiffer to stretch only 10 %
  // (Hooke: the stretch under the same load goes as 1 / ks), and lesson 08's advisor says what
  // step that stiffness needs.
  const double factor = soft.strain / 0.1;
  Scene stiff = load_scene_file(lesson_file("sagging-cloth.toml"));
  SpringSet& s = springs_of(stiff.world);
  for (size_t k = 0; k < s.size(); ++k)
    s.set_ks(k, factor * s.ks(k));
  const double dt_stiff = advise_time_step(stiff.world, dt, stiff.step_count()).dt_limit;
  const double dt_run = std::min(dt, 0.9 * dt_stiff);
  row(fmt::format("stiff springs, ks = {:.0f} N/m", 10.0 * factor), hang(0, factor, dt_run));
  fmt::print(
      "   * taut-cloth.toml. Built 1 m tall: a cloth that gives 10 % at most hangs about 1.1 m.\n"
      "   Springs stiff enough on their own ({:.1f} times the soft ones, so that the same load\n"
      "   stretches them 10 % instead of {:.0f} %) are stable only below dt = {} ms (lesson\n"
      "   08's advisor); they ran at 0.9 times that.\n\n",
      factor, 100.0 * soft.strain, round_down(1e3 * dt_stiff, 4));
}

void swinging_rope() {
  fmt::print("4. swinging-rope.toml: the largest link strain over the 4 s swing\n");
  for (const bool limited : {false, true}) {
    Scene scene = load_scene_file(lesson_file("swinging-rope.toml"));
    if (!limited) remove_limiter(scene.world);
    World& w = scene.world;
    double worst = 0.0, worst_t = 0.0;
    for (long n = 0; n < scene.step_count(); ++n) {
      w.step(scene.dt);
      const double s = max_strain(w);
      if (s > worst) worst = s, worst_t = w.t;
    }
    const Index last = scene.rope->first + scene.rope->count - 1;
    fmt::print("   {:>22}  largest strain {:.4f} at t = {:.2f} s; rope end at ({:.3f}, {:.3f})\n",
               limited ? "with [strain_limit]" : "without", worst, worst_t, w.particles.x(0, last),
               w.particles.x(1, last));
  }
  fmt::print("\n");
}

void jelly_cube() {
  Scene scene = load_scene_file(lesson_file("jelly-cube.toml"));
  World& w = scene.world;
  const Matrix3X& x = w.particles.x;
  fmt::print("5. jelly-cube.toml: the cube of 0.3 m dropped from 0.5 m\n");
  fmt::print("   {:>7}  {:>10}  {:>10}  {:>13}  {:>12}\n", "t [s]", "bottom [m]", "top [m]",
             "centre y [m]", "kinetic [J]");
  double lowest_top = 1e9, lowest_top_t = 0.0, touch = -1.0;
  const long every = std::lround(0.25 / scene.dt);
  for (long n = 1; n <= scene.step_count(); ++n) {
    w.step(scene.dt);
    if (touch < 0.0 && x.row(1).minCoeff() <= 1e-9) touch = w.t;
    if (touch >= 0.0 && x.row(1).maxCoeff() < lowest_top)
      lowest_top = x.row(1).maxCoeff(), lowest_top_t = w.t;
    if (n % every == 0) {
      fmt::print("   {:>7.2f}  {:>10.4f}  {:>10.4f}  {:>13.4f}  {:>12.3e}\n", w.t,
                 x.row(1).minCoeff(), x.row(1).maxCoeff(), x.row(1).mean(), w.kinetic_energy());
    }
  }
  fmt::print(
      "   It touches the ground at t = {:.3f} s (free fall: sqrt(2 * 0.5 / 9.8) = {:.3f} s);\n"
      "   squashed hardest at t = {:.3f} s, its top at {:.3f} m (0.300 m as built).\n",
      touch, std::sqrt(2.0 * 0.5 / 9.8), lowest_top_t, lowest_top);
}

void strain_table(const char* path) {
  Scene scene = load_scene_file(path);
  World& w = scene.world;
  fmt::print("{}: largest strain every 0.5 s{}\n", path,
             limiter_of(w) ? " (with [strain_limit])" : "");
  const long every = std::max(1L, std::lround(0.5 / scene.dt));
  for (long n = 1; n <= scene.step_count(); ++n) {
    w.step(scene.dt);
    if (n % every == 0 || n == scene.step_count())
      fmt::print("   t = {:>6.2f} s   {:.4f}\n", w.t, max_strain(w));
  }
}

}  // namespace

int main(int argc, char** argv) {
  return lesson::run("lesson09", [&] {
    if (argc > 1) {
      for (int a = 1; a < argc; ++a)
        strain_table(argv[a]);
      return;
    }
    one_spring();
    solid_counts();
    hanging_cloth();
    swinging_rope();
    jelly_cube();
  });
}
