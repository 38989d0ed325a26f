// Lesson 05: a particle meets the ground. Measures what the lesson's README quotes:
//   0. one collision response worked by hand (exercise ex05.1);
//   1. bounce heights against the e^2 law;
//   2. sliding distance against v0^2 / (2 mu_d g);
//   3. the lecture's simple friction against Coulomb friction on the same slide, at two steps.
// ./build/lesson05 runs on the reference solutions, ./build/lesson05-student on your exercises;
// while an exercise is still a stub, the program names it and exits with code 4.
#include <exception>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/methods.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

constexpr double g = 9.8;  // gravitational acceleration [m/s^2]

// One 1 kg particle at r with velocity v, gravity, and the ground y = 0.
World one_particle(const Vec3& r, const Vec3& v, const ContactMaterial& material,
                   Ground::Model model = Ground::Model::coulomb, double friction = 0.0) {
  World world;
  world.integrator = make_integrator("symplectic-euler");
  world.particles.add(r, v, 1.0);
  world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0, -g, 0)));
  world.post_step_effects.push_back(std::make_unique<Ground>(0.0, material, model, friction));
  return world;
}

void worked_response() {
  // n = +y, depth 0.01 m, e = 0.5, mu_s = 0.5, mu_d = 0.4; v = (4, -2, 0): v.n = -2,
  // j = 1.5 * 2 = 3, mu_s j = 1.5 < |v_t| = 4: it slides, v_t' = 4 (1 - 0.4 * 3 / 4) = 2.8,
  // v_n' = -0.5 * -2 = 1. With v = (1, -2, 0): |v_t| = 1 <= 1.5, it sticks: v' = (0, 1, 0).
  const Vec3 n = Vec3::UnitY();
  fmt::print("0. One response: n = (0, 1, 0), depth 0.01 m, e = 0.5, mu_s = 0.5, mu_d = 0.4\n");
  for (const Vec3& v : {Vec3(4, -2, 0), Vec3(1, -2, 0)}) {
    const PointState out = collision_response(Vec3(0, -0.01, 0), v, n, 0.01, 0.5, 0.5, 0.4);
    fmt::print(
        "   v = ({:g}, {:g}, 0) -> r' = ({:.4f}, {:.4f}, {:.4f}), v' = ({:.4f}, {:.4f}, {:.4f})\n",
        v.x(), v.y(), out.r.x(), out.r.y(), out.r.z(), out.v.x(), out.v.y(), out.v.z());
  }
  fmt::print("   by hand: v' = (2.8, 1, 0) (slides) and (0, 1, 0) (sticks); r' = (0, 0, 0)\n\n");
}

void bounce_table() {
  const double dt = 1e-3;  // [s]
  fmt::print("1. A ball dropped from 1 m, dt = {} s: the first four apexes [m]\n", dt);
  fmt::print("   {:>4}  {:>9}  {:>9}  {:>9}  {:>9}  {:>16}\n", "e", "apex 1", "apex 2", "apex 3",
             "apex 4", "e^2 (1, 2, 3, 4)");
  for (const double e : {1.0, 0.5}) {
    World world = one_particle(Vec3(0, 1, 0), Vec3::Zero(), ContactMaterial{e, 0.5, 0.4, 0.1});
    std::vector<double> apexes;  // heights where v.y turns from up to down [m]
    double vy_prev = 0.0;
    while (apexes.size() < 4 && world.t < 10.0) {
      world.step(dt);
      const double vy = world.particles.v(1, 0);
      if (vy_prev > 0.0 && vy <= 0.0) apexes.push_back(world.particles.x(1, 0));
      vy_prev = vy;
    }
    apexes.resize(4, 0.0);
    fmt::print("   {:>4}  {:>9.5f}  {:>9.5f}  {:>9.5f}  {:>9.5f}  {:g}, {:g}, {:g}, {:g}\n", e,
               apexes[0], apexes[1], apexes[2], apexes[3], e * e, e * e * e * e,
               e * e * e * e * e * e, e * e * e * e * e * e * e * e);
  }
  fmt::print("   A ball leaving the floor at e v rises e^2 as high as it fell.\n\n");
}

// Slides a particle from the origin at v0 along +x until it stops; returns the distance [m].
double slide(double v0, double dt, Ground::Model model, double friction) {
  World world = one_particle(Vec3::Zero(), Vec3(v0, 0, 0), ContactMaterial{0.0, 0.5, 0.4, 0.1},
                             model, friction);
  while (world.particles.v(0, 0) > 1e-6 && world.t < 20.0)
    world.step(dt);
  return world.particles.x(0, 0);
}

void sliding_table() {
  const double mu_d = 0.4;
  fmt::print("2. A puck launched along the floor, mu_s = 0.5, mu_d = {}: stopping distance [m]\n",
             mu_d);
  fmt::print("   {:>8}  {:>18}  {:>14}  {:>14}\n", "v0 [m/s]", "v0^2 / (2 mu_d g)", "dt = 1 ms",
             "dt = 0.1 ms");
  for (const double v0 : {1.0, 2.0, 4.0}) {
    fmt::print("   {:>8}  {:>18.4f}  {:>14.4f}  {:>14.4f}\n", v0, v0 * v0 / (2 * mu_d * g),
               slide(v0, 1e-3, Ground::Model::coulomb, 0.0),
               slide(v0, 1e-4, Ground::Model::coulomb, 0.0));
  }
  fmt::print("   Twice the speed, four times the distance; the step hardly matters.\n\n");
}

void simple_vs_coulomb() {
  const double friction = 0.01;  // the simple model's loss per contact
  fmt::print("3. The same slide with the lecture's simple model, friction = {} per contact [m]\n",
             friction);
  fmt::print("   {:>8}  {:>12}  {:>12}  {:>16}  {:>16}\n", "v0 [m/s]", "Coulomb 1 ms",
             "Coulomb 0.5", "simple 1 ms", "simple 0.5 ms");
  for (const double v0 : {2.0, 4.0}) {
    fmt::print("   {:>8}  {:>12.4f}  {:>12.4f}  {:>16.4f}  {:>16.4f}\n", v0,
               slide(v0, 1e-3, Ground::Model::coulomb, 0.0),
               slide(v0, 5e-4, Ground::Model::coulomb, 0.0),
               slide(v0, 1e-3, Ground::Model::simple, friction),
               slide(v0, 5e-4, Ground::Model::simple, friction));
  }
  fmt::print(
      "   The simple model takes a fixed fraction per contact: halve the step, twice the contacts\n"
      "   per second, and the puck stops in half the distance. Its distance grows like v0,\n"
      "   not v0^2.\n");
}

}  // namespace

int main() {
  return lesson::run("lesson05", [&] {
    worked_response();
    bounce_table();
    sliding_table();
    simple_vs_coulomb();
  });
}
