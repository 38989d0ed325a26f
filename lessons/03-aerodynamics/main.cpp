// Lesson 03: air on a triangle, on a falling sheet and on a falling ball, measured.
//
// Three experiments, each built with the C++ API (no scene file), each against an estimate:
//   1. one still triangle as a 10 m/s wind turns from face-on to edge-on;
//   2. the sheet of falling-sheet.toml dropped with and without air: speed after 2 s;
//   3. a ping-pong ball under fluid drag: its speed against the exact v_t tanh(g t / v_t).
// ./build/lesson03 runs on the reference solutions, ./build/lesson03-student on your exercises;
// while an exercise is still a stub, the program names it and exits with code 4.
#include <cmath>
#include <exception>
#include <memory>
#include <numbers>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/methods.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

constexpr double g = 9.8;            // gravitational acceleration [m/s^2]
constexpr double rho = kAirDensity;  // 1.225 kg/m^3
constexpr double pi = std::numbers::pi;
constexpr double density = 0.1;  // the sheet's mass per area [kg/m^2]: 1 m^2 weighs 0.1 kg

// --- 1. One triangle in a turning wind ------------------------------------------------------

void turning_wind_table() {
  // Right triangle with legs of 1 m in the x-y plane: n = (0, 0, 1), a0 = 0.5 m^2. It stands
  // still; the wind of 10 m/s blows at `angle` from its normal, onto its face.
  const Vec3 r1 = Vec3::Zero(), r2(1.0, 0.0, 0.0), r3(0.0, 1.0, 0.0), still = Vec3::Zero();
  const double speed = 10.0, cd = 1.0, a0 = 0.5;
  const double f0 = 0.5 * rho * speed * speed * cd * a0;  // face-on force, 30.625 N
  fmt::print("1. A still triangle (a0 = 0.5 m^2) in a 10 m/s wind at an angle to its normal\n");
  fmt::print("   face-on force F0 = 1/2 rho |v|^2 cd a0 = {:.3f} N\n", f0);
  fmt::print("   {:>5}  {:>8}  {:>9}  {:>11}  {:>11}  {:>12}  {:>13}\n", "angle", "|f| [N]",
             "F0 cos", "along wind", "F0 cos^2", "across wind", "F0 cos sin");
  for (const double degrees : {0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0}) {
    const double angle = degrees * pi / 180.0;
    const Vec3 wind_dir(std::sin(angle), 0.0, -std::cos(angle));  // onto the face, toward -z
    const Vec3 f = aerodynamic_force(r1, r2, r3, still, still, still, speed * wind_dir, rho, cd);
    const double along = f.dot(wind_dir);                 // the part that pushes downwind
    const double across = (f - along * wind_dir).norm();  // the part at right angles to it
    const double c = std::cos(angle), s = std::sin(angle);
    fmt::print("   {:>5}  {:>8.3f}  {:>9.3f}  {:>11.3f}  {:>11.3f}  {:>12.3f}  {:>13.3f}\n",
               degrees, f.norm(), f0 * c, along, f0 * c * c, across, f0 * c * s);
  }
  fmt::print(
      "   The force is along the normal, of size F0 cos: downwind it pushes F0 cos^2, and\n"
      "   F0 cos sin sideways. Edge-on (90 degrees) the air slides past and pushes nothing.\n\n");
}

// --- 2. A sheet dropped flat ----------------------------------------------------------------

// The sheet of falling-sheet.toml: 11 x 11 particles 0.1 m apart (1 m x 1 m), 0.1 kg, lying
// flat at y = 10 m. If `by_area`, each particle gets the mass of a third of its triangles'
// area instead of an equal share (a scene's mass_by = "area").
World falling_sheet(bool with_air, bool by_area) {
  World world;
  world.integrator = make_integrator("symplectic-euler");
  ClothSpec spec;
  spec.rows = spec.cols = 11;
  spec.spacing = 0.1;
  spec.origin = Vec3(-0.5, 10.0, -0.5);
  spec.horizontal = true;
  spec.mass = density * 1.0;
  spec.mass_by_area = by_area;  // a third of each triangle's mass, a0 = spacing^2 / 2, a corner
  Particles& p = world.particles;
  const ClothGrid grid = add_cloth(p, spec);
  world.triangles = grid_triangles(grid);
  SpringSet springs;
  add_spring_family(springs, structural_pairs(grid.rows, grid.cols), grid.first, 100.0, 0.02, p.x);
  add_spring_family(springs, shear_pairs(grid.rows, grid.cols), grid.first, 100.0, 0.02, p.x);
  world.force_effects.push_back(std::make_unique<SpringDampers>("springs", std::move(springs)));
  world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0.0, -g, 0.0)));
  if (with_air) {
    world.force_effects.push_back(
        std::make_unique<Aerodynamics>(world.triangles, rho, 1.0, Vec3::Zero()));
  }
  return world;
}

void falling_sheet_table() {
  const double area = 1.0, mass = density * area, cd = 1.0;          // [m^2], [kg]
  const double v_t = std::sqrt(2.0 * mass * g / (rho * cd * area));  // flat: 1.265 m/s
  fmt::print("2. A 1 m x 1 m sheet of 0.1 kg dropped flat, dt = 0.001 s, after t = 2 s\n");
  fmt::print("   terminal speed if it stays flat: sqrt(2 m g / (rho cd A)) = {:.4f} m/s\n", v_t);
  fmt::print("   {:<26}  {:>8}  {:>8}  {:>7}  {:>12}  {:>15}\n", "case", "v [m/s]", "drop [m]",
             "cup [m]", "A_seen [m^2]", "v_t for A_seen");
  struct Case {
    std::string_view label;
    bool with_air, by_area;
  };
  for (const Case& c :
       {Case{"no air", false, false}, Case{"air, equal masses (scene)", true, false},
        Case{"air, masses by area", true, true}}) {
    World world = falling_sheet(c.with_air, c.by_area);
    for (int s = 0; s < 2000; ++s)
      world.step(0.001);
    const Matrix3X& x = world.particles.x;
    // The area the falling air meets: a0 n_y^2 = n*_y^2 / (2 |n*|) per triangle (README).
    double seen = 0.0;
    for (const Triangle& t : world.triangles) {
      const Vec3 n_star = (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0]));
      seen += 0.5 * n_star.y() * n_star.y() / n_star.norm();
    }
    const double speed = -world.momentum().y() / mass;  // mean downward speed
    fmt::print("   {:<26}  {:>8.4f}  {:>8.4f}  {:>7.4f}  {:>12.4f}  {:>15.4f}\n", c.label, speed,
               10.0 - x.row(1).mean(), x.row(1).maxCoeff() - x.row(1).minCoeff(), seen,
               std::sqrt(2.0 * mass * g / (rho * cd * seen)));
  }
  fmt::print(
      "   Without air the sheet falls at g t = 19.6 m/s. With equal masses the rim, which\n"
      "   catches less air per kilogram, sags into a cup that shows the air less area.\n\n");
}

// --- 3. Fluid drag on a ball ----------------------------------------------------------------

void drag_table() {
  // A ping-pong ball: 2.7 g, radius 2 cm, cd = 0.47 (a sphere), dropped from rest in still air.
  const double m = 0.0027, a = pi * 0.02 * 0.02, cd = 0.47, dt = 0.001;
  const double v_t = std::sqrt(2.0 * m * g / (rho * cd * a));  // drag = weight: 8.552 m/s
  World world;
  world.integrator = make_integrator("symplectic-euler");
  world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0.0, -g, 0.0)));
  world.force_effects.push_back(std::make_unique<FluidDrag>(rho, cd, a, Vec3::Zero()));
  world.particles.add(Vec3::Zero(), Vec3::Zero(), m);
  fmt::print("3. A ping-pong ball (2.7 g, a = {:.6f} m^2, cd = 0.47) dropped in still air\n", a);
  fmt::print("   terminal speed sqrt(2 m g / (rho cd a)) = {:.4f} m/s, dt = {} s\n", v_t, dt);
  fmt::print("   {:>5}  {:>14}  {:>21}  {:>10}\n", "t [s]", "speed [m/s]", "v_t tanh(g t/v_t)",
             "difference");
  long done = 0;
  for (const double t : {0.25, 0.5, 1.0, 2.0, 4.0}) {
    for (; done < std::lround(t / dt); ++done)
      world.step(dt);
    const double exact = v_t * std::tanh(g * t / v_t);
    const double speed = -world.particles.v(1, 0);
    fmt::print("   {:>5}  {:>14.4f}  {:>21.4f}  {:>+10.4f}\n", t, speed, exact, speed - exact);
  }
  fmt::print(
      "   It never passes v_t: once drag equals weight there is nothing left to speed it up.\n");
}

}  // namespace

int main() {
  return lesson::run("lesson03", [&] {
    turning_wind_table();
    falling_sheet_table();
    drag_table();
  });
}
